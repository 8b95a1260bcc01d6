#include "common/sim/sphere_state_solve.h"

#include <algorithm>
#include <limits>
#include <optional>

#include "common/util/error.h"

namespace cohaptic {
namespace {

constexpr double kNone = std::numeric_limits<double>::infinity();

const SphereConstraint& no_obstacle() {
  static const SphereConstraint none{-1, kNone, Eigen::Vector3d::Zero(), -1};
  return none;
}

}  // namespace

SphereStateSolve::SphereStateSolve(const ElasticBody& body, ComplianceColumns& columns,
                                   std::vector<SphereConstraint> obstacles)
    : body_(body),
      columns_(columns),
      touchable_(triangle_nodes(body.surface, body.touchable_triangles)),
      obstacle_(std::move(obstacles)),
      directions_(body.contact_normals),
      normal_(columns, body.dofs, directions_),
      contact_(static_cast<int>(normal_.capacity())) {
  for (std::size_t node = 0; node < obstacle_.size(); ++node)
    if (obstacle_[node].obstacle >= 0) obstacle_nodes_.push_back(static_cast<int>(node));
}

void SphereStateSolve::set_candidates(const std::vector<int>& nodes, IncrementalCondensation& condensation,
                                      const Eigen::VectorXd& boundary_displacement) {
  std::vector<char> wanted(static_cast<std::size_t>(body_.mesh.node_count()), 0);
  for (int node : nodes) wanted[static_cast<std::size_t>(node)] = 1;
  // A member whose node leaves, or takes a new direction, gives up its slot, which another
  // node may take.
  const std::vector<int> members(contact_.members().begin(), contact_.members().end());
  for (int slot : members) {
    const int node = normal_.node_of(slot);
    if (!wanted[static_cast<std::size_t>(node)] || !normal_.current(node)) contact_.remove(slot);
  }
  const bool w_changed = normal_.update(nodes, condensation, boundary_displacement);
  if (w_changed || contact_.capacity() < normal_.capacity()) {
    const std::vector<int> kept(contact_.members().begin(), contact_.members().end());
    if (contact_.capacity() < normal_.capacity()) contact_ = IncrementalContactSolve(static_cast<int>(normal_.capacity()));
    if (!contact_.start_from(normal_.w(), kept)) contact_.clear();
  }
}

StateSolution SphereStateSolve::solve(IncrementalCondensation& condensation, std::span<const int> patch_nodes,
                                      std::span<const SphereTool> spheres, const Eigen::VectorXd& boundary_displacement) {
  const DofMap& dofs = body_.dofs;
  const auto obstacle_of = [&](int node) -> const SphereConstraint& {
    return obstacle_.empty() ? no_obstacle() : obstacle_[static_cast<std::size_t>(node)];
  };
  const auto constraint_of = [&](int node) {
    return node_constraint(body_.mesh.nodes.col(node), body_.contact_normals.col(node),
                           dofs.fixed_axes[static_cast<std::size_t>(node)], spheres, obstacle_of(node));
  };
  std::vector<char> listed(static_cast<std::size_t>(body_.mesh.node_count()), 0);
  std::vector<int> candidates;
  const auto add = [&](int node) {
    if (listed[static_cast<std::size_t>(node)] || condensation.in_boundary(node) ||
        (!holdable(body_.contact_normals.col(node), dofs.fixed_axes[static_cast<std::size_t>(node)]) &&
         obstacle_of(node).obstacle < 0))
      return false;
    listed[static_cast<std::size_t>(node)] = 1;
    candidates.push_back(node);
    return true;
  };
  // The touchable nodes within `band` of a sphere (their gap) join the candidates.
  const auto add_band = [&](double band) {
    bool added = false;
    for (int node : touchable_)
      if (!listed[static_cast<std::size_t>(node)])
        if (const auto constraint = sphere_constraint(body_.mesh.nodes.col(node), body_.contact_normals.col(node),
                                                      dofs.fixed_axes[static_cast<std::size_t>(node)], spheres);
            constraint && constraint->gap < band)
          added |= add(node);
    return added;
  };
  for (int node : patch_nodes) add(node);
  add_band(band_);
  for (int node : obstacle_candidates_) add(node);

  for (;;) {
    // Each candidate pushes along its constraint's direction (its own normal if none holds it).
    std::vector<std::optional<SphereConstraint>> constraints;
    for (int node : candidates) {
      constraints.push_back(constraint_of(node));
      directions_.col(node) = constraints.back() ? constraints.back()->normal : body_.contact_normals.col(node);
    }
    set_candidates(candidates, condensation, boundary_displacement);
    std::vector<int> index_of(static_cast<std::size_t>(body_.mesh.node_count()), -1);
    for (std::size_t i = 0; i < candidates.size(); ++i) index_of[static_cast<std::size_t>(candidates[i])] = static_cast<int>(i);
    const Eigen::Index capacity = normal_.capacity();
    clearance_.setConstant(capacity, kNone);
    tool_.assign(static_cast<std::size_t>(capacity), -1);
    for (int slot = 0; slot < normal_.slot_count(); ++slot) {
      const int node = normal_.node_of(slot);
      if (node < 0) continue;
      if (const auto& constraint = constraints[static_cast<std::size_t>(index_of[static_cast<std::size_t>(node)])]) {
        clearance_[slot] = constraint->gap + normal_.free_clearance()[slot];
        tool_[static_cast<std::size_t>(slot)] = constraint->tool;
      }
    }
    if (!contact_.solve(normal_.w(), clearance_, normal_.nonnegative_rows(), kNone).solved)
      throw NumericalError("the sphere contact's normal compliance is not positive definite");

    StateSolution state;
    state.tool_forces.assign(spheres.size(), Eigen::Vector3d::Zero());
    std::vector<double> forces;
    std::vector<char> pushed(listed.size(), 0);
    obstacle_pushed_ = 0;
    double deepest = 0;  // [m]: the deepest pushed node's penetration, or B's largest normal move
    for (int p = 0; p < static_cast<int>(contact_.members().size()); ++p) {
      const int slot = contact_.members()[static_cast<std::size_t>(p)];
      const double push = contact_.member_push(p);
      if (!(push > 0)) continue;
      const int node = normal_.node_of(slot);
      pushed[static_cast<std::size_t>(node)] = 1;
      const Eigen::Vector3d force = push * normal_.normal(slot);
      for (int axis = 0; axis < 3; ++axis)
        if (!dofs.is_fixed(node, axis)) {
          state.contact_dofs.push_back(3 * node + axis);
          forces.push_back(force[axis]);
        }
      if (const int tool = tool_[static_cast<std::size_t>(slot)]; tool >= 0)
        state.tool_forces[static_cast<std::size_t>(tool)] += force;
      else
        ++obstacle_pushed_;
      deepest = std::max(deepest, normal_.free_clearance()[slot] - clearance_[slot]);
    }
    for (int slot = 0; slot < normal_.slot_count(); ++slot)
      if (normal_.node_of(slot) >= 0) deepest = std::max(deepest, std::abs(normal_.free_clearance()[slot]));
    state.contact_forces = Eigen::Map<const Eigen::VectorXd>(forces.data(), static_cast<Eigen::Index>(forces.size()));
    // Every touchable node within twice that of a sphere must have been a candidate; else
    // they join and the state is solved again.
    const double band = kBandPerDepth * deepest;
    const bool wider = band > band_;
    band_ = band;
    if (wider && add_band(band)) continue;
    solve_boundary_forces(columns_, condensation, dofs, boundary_displacement, state);
    if (obstacle_nodes_.empty()) return state;

    // The obstacles: every candidate, and every node that could have come within
    // kObstacleJoin of its obstacle (its rest gap less than the band, plus the margin), is
    // checked in the solved state.
    std::vector<int> checked;
    for (int node : obstacle_nodes_)
      if (listed[static_cast<std::size_t>(node)] || obstacle_of(node).gap < band + kObstacleLeave) checked.push_back(node);
    const Eigen::Matrix3Xd u = displacement_of_nodes(columns_, state, checked);
    bool joined = false;
    std::vector<int> kept;
    for (std::size_t k = 0; k < checked.size(); ++k) {
      const int node = checked[k];
      const SphereConstraint& obstacle = obstacle_of(node);
      const double clearance = obstacle.gap + obstacle.normal.dot(u.col(static_cast<Eigen::Index>(k)));
      if (!listed[static_cast<std::size_t>(node)]) {
        if (clearance < kObstacleJoin) joined |= add(node);
        continue;
      }
      const int index = index_of[static_cast<std::size_t>(node)];
      const bool held_by_obstacle = constraints[static_cast<std::size_t>(index)] &&
                                    constraints[static_cast<std::size_t>(index)]->obstacle >= 0;
      if (held_by_obstacle && (clearance < kObstacleLeave || pushed[static_cast<std::size_t>(node)])) kept.push_back(node);
    }
    if (joined) continue;
    obstacle_candidates_ = std::move(kept);
    obstacle_rows_.clear();
    obstacle_row_gaps_.clear();
    for (std::size_t i = 0; i < candidates.size(); ++i)
      if (constraints[i] && constraints[i]->obstacle >= 0) obstacle_rows_.push_back(candidates[i]);
    std::sort(obstacle_rows_.begin(), obstacle_rows_.end());
    for (int node : obstacle_rows_) obstacle_row_gaps_.push_back(obstacle_of(node).gap);
    return state;
  }
}

}  // namespace cohaptic
