// The node translation and point contact models' part of Simulation's step (simulation.h).
#include "common/sim/simulation.h"

#include <limits>

namespace cohaptic {

Simulation::TriangleContacts::TriangleContacts(std::span<const ObstacleDistance> obstacles,
                                               const Eigen::Matrix3Xd& surface_points)
    : clearance_(obstacles, surface_points) {}

bool Simulation::TriangleContacts::settle(Simulation& s, HeldSetUpdate& /*update*/) {
  bool changed = false;
  for (int pass = 0; pass < s.options_.obstacle_iterations && !s.obstacles_.empty(); ++pass) {
    if (!update_obstacle_contacts(s)) break;
    changed = true;
  }
  return changed;
}

StateSolution Simulation::TriangleContacts::solve(Simulation& s) const {
  return s.solve(s.pressing_contacts());
}

StateSolution Simulation::TriangleContacts::solve_unloaded(Simulation& s) const {
  return solve_state(s.columns_, s.condensation_, s.body_.dofs, s.pressing_contacts(),
                     s.boundary_dof_displacement(), s.options_.ir.contact_model);
}

StateSolution Simulation::TriangleContacts::solve_previous(Simulation& s) const {
  return s.solve(previous_contacts_);
}

void Simulation::TriangleContacts::remember_step(const Simulation& s) {
  previous_contacts_ = s.pressing_contacts();
}

int Simulation::TriangleContacts::obstacle_nodes(const Simulation& s) const {
  int held_by_obstacles = 0;
  for (const auto& [node, held] : s.held_) held_by_obstacles += held.obstacle >= 0;
  return held_by_obstacles;
}

bool Simulation::TriangleContacts::update_obstacle_contacts(Simulation& s) {
  const ElasticBody& body = s.body_;
  const StateSolution state = s.solve();
  // Held nodes whose obstacle would have to pull (holding force into the obstacle) go free.
  std::vector<int> pulling;
  for (std::size_t b = 0, dof = 0; b < s.condensation_.boundary_nodes().size(); ++b) {
    const int node = s.condensation_.boundary_nodes()[b];
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    for (int axis = 0; axis < 3; ++axis)
      if (!body.dofs.is_fixed(node, axis))
        force[axis] = state.boundary_forces[static_cast<Eigen::Index>(dof++)];
    const HeldNode& held = s.held_.at(node);
    if (held.obstacle < 0) continue;
    const Eigen::Vector3d at = body.mesh.nodes.col(node) + held.displacement;
    if (force.dot(s.obstacles_[held.obstacle].closest_point(at).normal) < 0)
      pulling.push_back(node);
  }
  // Free nodes whose displaced position penetrates an obstacle are held on it. Only nodes
  // that may have reached one since their last query are queried (ObstacleClearance).
  const Eigen::Matrix3Xd u = displacement_of_nodes(s.columns_, state, body.surface.nodes);
  near_obstacles_.clear();  // as of this pass's state
  std::vector<std::pair<int, HeldNode>> penetrating;
  for (std::size_t i = 0; i < body.surface.nodes.size(); ++i) {
    const int node = body.surface.nodes[i];
    if (s.held_.count(node) || s.under_tool_[node] || body.dofs.fixed_axes[node] == kAllAxes)
      continue;
    const Eigen::Vector3d rest = body.mesh.nodes.col(node);
    const Eigen::Vector3d moved = rest + u.col(static_cast<Eigen::Index>(i));
    if (const double estimate = clearance_.estimate(i, moved);
        estimate < s.options_.near_obstacle_distance && !s.columns_.has_column(node))
      near_obstacles_.push_back({node, estimate});
    if (clearance_.certainly_clear(i, moved)) continue;
    ObstaclePoint nearest{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                          std::numeric_limits<double>::infinity(), -1};
    for (int o = 0; o < static_cast<int>(s.obstacles_.size()); ++o) {
      const ObstaclePoint hit = s.obstacles_[o].closest_point(moved);
      if (hit.signed_distance < nearest.signed_distance) nearest = hit;
      if (hit.signed_distance >= 0) continue;
      penetrating.push_back({node, {hit.point - rest, o}});
      break;
    }
    clearance_.record(i, moved, nearest.signed_distance, nearest.normal);
  }
  for (int node : pulling) s.release(node);
  std::vector<int> joining;
  for (const auto& entry : penetrating) joining.push_back(entry.first);
  s.columns_.compute_columns(joining);  // one multi-right-hand-side solve for all that join
  for (const auto& [node, held] : penetrating) s.hold(node, held);
  return !pulling.empty() || !penetrating.empty();
}

}  // namespace cohaptic
