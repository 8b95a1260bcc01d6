#include "common/sim/sphere_state_solve.h"

#include <algorithm>
#include <iterator>
#include <limits>
#include <optional>

#include "common/condense/dense_kernels.h"
#include "common/contact/obstacle_constraints.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

constexpr double kNone = std::numeric_limits<double>::infinity();

// The nodes that `obstacles` constrain, ascending.
std::vector<int> obstacle_nodes_of(std::span<const SphereConstraint> obstacles) {
  std::vector<int> nodes;
  for (std::size_t node = 0; node < obstacles.size(); ++node)
    if (obstacles[node].obstacle >= 0) nodes.push_back(static_cast<int>(node));
  return nodes;
}

// How many nodes can be candidates at once: the touchable ones and the obstacles'.
Eigen::Index candidate_bound(std::span<const int> touchable, std::span<const int> obstacle_nodes) {
  std::vector<int> all;
  std::set_union(touchable.begin(), touchable.end(), obstacle_nodes.begin(), obstacle_nodes.end(),
                 std::back_inserter(all));
  return static_cast<Eigen::Index>(all.size());
}

}  // namespace

SphereStateSolve::SphereStateSolve(const ElasticBody& body, ComplianceColumns& columns,
                                   std::vector<SphereConstraint> obstacles)
    : body_(body),
      columns_(columns),
      touchable_(triangle_nodes(body.surface, body.touchable_triangles)),
      obstacle_(std::move(obstacles)),
      obstacle_nodes_(obstacle_nodes_of(obstacle_)),
      directions_(body.contact_normals),
      normal_(columns, body.dofs, candidate_bound(touchable_, obstacle_nodes_)),
      contact_(static_cast<int>(normal_.capacity())) {}

void SphereStateSolve::set_candidates(const std::vector<int>& nodes,
                                      IncrementalCondensation& condensation,
                                      const Eigen::VectorXd& boundary_displacement) {
  std::vector<char> wanted(static_cast<std::size_t>(body_.mesh.node_count()), 0);
  for (int node : nodes) wanted[static_cast<std::size_t>(node)] = 1;
  // A member whose node leaves, or takes a new direction, gives up its slot, which another
  // node may take.
  const std::vector<int> members(contact_.members().begin(), contact_.members().end());
  for (int slot : members) {
    const int node = normal_.node_of(slot);
    if (!wanted[static_cast<std::size_t>(node)] || !normal_.current(node, directions_.col(node)))
      contact_.remove(slot);
  }
  const bool w_changed = normal_.update(nodes, directions_, condensation, boundary_displacement);
  if (w_changed || contact_.capacity() < normal_.capacity()) {
    const std::vector<int> kept(contact_.members().begin(), contact_.members().end());
    if (contact_.capacity() < normal_.capacity())
      contact_ = IncrementalContactSolve(static_cast<int>(normal_.capacity()));
    if (!contact_.start_from(normal_.w(), kept)) contact_.clear();
  }
}

StateSolution SphereStateSolve::solve(IncrementalCondensation& condensation,
                                      std::span<const int> patch_nodes,
                                      std::span<const SphereTool> spheres,
                                      const Eigen::VectorXd& boundary_displacement) {
  const DofMap& dofs = body_.dofs;
  obstacle_rows_.clear();  // until this solve finds them (a solve that throws leaves none)
  obstacle_contacts_.clear();
  const auto constraint_of = [&](int node) {
    return node_constraint(body_.mesh.nodes.col(node), body_.contact_normals.col(node),
                           dofs.fixed_axes[static_cast<std::size_t>(node)], spheres,
                           obstacle_at(obstacle_, node));
  };
  std::vector<int> candidates;
  std::vector<int> index_of(static_cast<std::size_t>(body_.mesh.node_count()),
                            -1);  // among the candidates
  const auto listed = [&](int node) { return index_of[static_cast<std::size_t>(node)] >= 0; };
  const auto add = [&](int node) {
    if (listed(node) || condensation.in_boundary(node) ||
        (!holdable(body_.contact_normals.col(node),
                   dofs.fixed_axes[static_cast<std::size_t>(node)]) &&
         !obstacle_at(obstacle_, node)))
      return false;
    index_of[static_cast<std::size_t>(node)] = static_cast<int>(candidates.size());
    candidates.push_back(node);
    return true;
  };
  // The touchable nodes within `band` of a sphere (their gap) join the candidates.
  const auto add_band = [&](double band) {
    bool added = false;
    for (int node : touchable_)
      if (!listed(node))
        if (const auto constraint =
                sphere_constraint(body_.mesh.nodes.col(node), body_.contact_normals.col(node),
                                  dofs.fixed_axes[static_cast<std::size_t>(node)], spheres);
            constraint && constraint->gap < band)
          added |= add(node);
    return added;
  };
  // The obstacles' nodes whose rest gap is within `band` (plus kObstacleBandMargin) join too.
  // Their band never narrows: a node that joined stays, so that the many nodes along an
  // obstacle do not leave and join again as the presses deepen and ease.
  const auto add_obstacle_band = [&](double band) {
    obstacle_band_ = std::max(obstacle_band_, band);
    bool added = false;
    for (int node : obstacle_nodes_)
      if (!listed(node) &&
          obstacle_[static_cast<std::size_t>(node)].gap < obstacle_band_ + kObstacleBandMargin)
        added |= add(node);
    return added;
  };
  for (int node : patch_nodes) add(node);
  add_band(band_);
  add_obstacle_band(band_);

  for (;;) {
    // Each candidate pushes along its constraint's direction (its own normal if none holds it).
    std::vector<std::optional<SphereConstraint>> constraints;
    for (int node : candidates) {
      constraints.push_back(constraint_of(node));
      directions_.col(node) =
          constraints.back() ? constraints.back()->normal : body_.contact_normals.col(node);
    }
    set_candidates(candidates, condensation, boundary_displacement);
    const auto constraint_of_slot = [&](int slot) -> const std::optional<SphereConstraint>& {
      return constraints[static_cast<std::size_t>(
          index_of[static_cast<std::size_t>(normal_.node_of(slot))])];
    };
    const Eigen::Index capacity = normal_.capacity();
    clearance_.setConstant(capacity, kNone);
    tool_.assign(static_cast<std::size_t>(capacity), -1);
    for (int slot = 0; slot < normal_.slot_count(); ++slot) {
      if (normal_.node_of(slot) < 0) continue;
      if (const auto& constraint = constraint_of_slot(slot)) {
        clearance_[slot] = constraint->gap + normal_.free_clearance()[slot];
        tool_[static_cast<std::size_t>(slot)] = constraint->tool;
      }
    }
    if (!contact_.solve(normal_.w(), clearance_, normal_.nonnegative_rows(), kNone).solved)
      throw NumericalError("the sphere contact's normal compliance is not positive definite");

    StateSolution state;
    state.tool_forces.assign(spheres.size(), Eigen::Vector3d::Zero());
    std::vector<double> forces;
    obstacle_pushed_ = 0;
    double deepest = 0;  // [m]: the deepest pushed node's penetration, or B's largest normal move
    for (int p = 0; p < static_cast<int>(contact_.members().size()); ++p) {
      const int slot = contact_.members()[static_cast<std::size_t>(p)];
      const double push = contact_.member_push(p);
      if (!(push > 0)) continue;
      const int node = normal_.node_of(slot);
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
      if (normal_.node_of(slot) >= 0)
        deepest = std::max(deepest, std::abs(normal_.free_clearance()[slot]));
    state.contact_forces =
        Eigen::Map<const Eigen::VectorXd>(forces.data(), static_cast<Eigen::Index>(forces.size()));
    // Every touchable node within twice that of a sphere, and every obstacle node within it
    // of its obstacle, must have been a candidate; else they join and the state is solved again.
    const double band = kBandPerDepth * deepest;
    const bool wider = band > band_;
    band_ = band;
    if (wider) {
      const bool sphere_candidates_joined =
          add_band(band);  // both run: each adds its own candidates
      const bool obstacle_candidates_joined = add_obstacle_band(band);
      if (sphere_candidates_joined || obstacle_candidates_joined) continue;
    }
    solve_boundary_forces(columns_, condensation, dofs, boundary_displacement, state);
    if (!obstacle_nodes_.empty()) find_obstacle_rows(patch_nodes);
    return state;
  }
}

void SphereStateSolve::find_obstacle_rows(std::span<const int> patch_nodes) {
  // Each obstacle candidate's clearance in the solved state, w = q + W lambda: from the
  // solve's last pass where it read W lambda for every slot, else down the candidate's
  // column of W (symmetric: contiguous, where its row is not).
  const std::span<const int> members = contact_.members();
  const std::span<const double> pushes = contact_.member_pushes();
  const std::span<const double> w_push = contact_.w_push();
  std::vector<char> in_patch(static_cast<std::size_t>(body_.mesh.node_count()), 0);
  for (int node : patch_nodes) in_patch[static_cast<std::size_t>(node)] = 1;
  obstacle_rows_.clear();
  obstacle_contacts_.clear();
  for (int slot = 0; slot < normal_.slot_count(); ++slot) {
    const int node = normal_.node_of(slot);
    if (node < 0 || tool_[static_cast<std::size_t>(slot)] >= 0 || clearance_[slot] == kNone)
      continue;  // no obstacle's
    const double clearance =
        clearance_[slot] +
        (static_cast<std::size_t>(slot) < w_push.size()
             ? w_push[static_cast<std::size_t>(slot)]
             : gathered_dot(normal_.w().col(slot).data(), members.data(), pushes.data(),
                            static_cast<Eigen::Index>(members.size())));
    const bool pushed = contact_.push(slot) > 0;
    if (pushed || clearance < kObstacleJoin) obstacle_contacts_.push_back(node);
    if (pushed || clearance < kObstacleReach || in_patch[static_cast<std::size_t>(node)])
      obstacle_rows_.push_back(node);
  }
  std::sort(obstacle_rows_.begin(), obstacle_rows_.end());
  std::sort(obstacle_contacts_.begin(), obstacle_contacts_.end());
}

}  // namespace cohaptic
