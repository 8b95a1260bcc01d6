#include "common/sim/sphere_state_solve.h"

#include <algorithm>
#include <limits>

#include "common/util/error.h"

namespace cohaptic {

SphereStateSolve::SphereStateSolve(const ElasticBody& body, ComplianceColumns& columns)
    : body_(body),
      columns_(columns),
      touchable_(triangle_nodes(body.surface, body.touchable_triangles)),
      normal_(columns, body.dofs, body.contact_normals),
      contact_(static_cast<int>(normal_.capacity())) {}

void SphereStateSolve::set_candidates(const std::vector<int>& nodes, IncrementalCondensation& condensation,
                                      const Eigen::VectorXd& boundary_displacement) {
  std::vector<char> wanted(static_cast<std::size_t>(body_.mesh.node_count()), 0);
  for (int node : nodes) wanted[static_cast<std::size_t>(node)] = 1;
  // A member whose node leaves gives up its slot, which another node may take.
  const std::vector<int> members(contact_.members().begin(), contact_.members().end());
  for (int slot : members)
    if (!wanted[static_cast<std::size_t>(normal_.node_of(slot))]) contact_.remove(slot);
  const bool w_changed = normal_.update(nodes, condensation, boundary_displacement);
  if (w_changed || contact_.capacity() < normal_.capacity()) {
    const std::vector<int> kept(contact_.members().begin(), contact_.members().end());
    if (contact_.capacity() < normal_.capacity()) contact_ = IncrementalContactSolve(static_cast<int>(normal_.capacity()));
    if (!contact_.start_from(normal_.w(), kept)) contact_.clear();
  }
}

StateSolution SphereStateSolve::solve(IncrementalCondensation& condensation, std::span<const int> patch_nodes,
                                      std::span<const SphereTool> spheres, const Eigen::VectorXd& boundary_displacement) {
  constexpr double kNone = std::numeric_limits<double>::infinity();
  const DofMap& dofs = body_.dofs;
  std::vector<char> listed(static_cast<std::size_t>(body_.mesh.node_count()), 0);
  std::vector<int> candidates;
  const auto add = [&](int node) {
    if (listed[static_cast<std::size_t>(node)] || condensation.in_boundary(node) ||
        !holdable(body_.contact_normals.col(node), dofs.fixed_axes[static_cast<std::size_t>(node)]))
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

  for (;;) {
    set_candidates(candidates, condensation, boundary_displacement);
    const Eigen::Index capacity = normal_.capacity();
    clearance_.setConstant(capacity, kNone);
    tool_.assign(static_cast<std::size_t>(capacity), -1);
    for (int slot = 0; slot < normal_.slot_count(); ++slot) {
      const int node = normal_.node_of(slot);
      if (node < 0) continue;
      if (const auto constraint = sphere_constraint(body_.mesh.nodes.col(node), normal_.normal(slot),
                                                    dofs.fixed_axes[static_cast<std::size_t>(node)], spheres)) {
        clearance_[slot] = constraint->gap + normal_.free_clearance()[slot];
        tool_[static_cast<std::size_t>(slot)] = constraint->tool;
      }
    }
    if (!contact_.solve(normal_.w(), clearance_, normal_.nonnegative_rows(), kNone).solved)
      throw NumericalError("the sphere contact's normal compliance is not positive definite");

    StateSolution state;
    state.tool_forces.assign(spheres.size(), Eigen::Vector3d::Zero());
    std::vector<double> forces;
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
      state.tool_forces[static_cast<std::size_t>(tool_[static_cast<std::size_t>(slot)])] += force;
      deepest = std::max(deepest, normal_.free_clearance()[slot] - clearance_[slot]);
    }
    for (int slot = 0; slot < normal_.slot_count(); ++slot)
      if (normal_.node_of(slot) >= 0) deepest = std::max(deepest, std::abs(normal_.free_clearance()[slot]));
    state.contact_forces = Eigen::Map<const Eigen::VectorXd>(forces.data(), static_cast<Eigen::Index>(forces.size()));
    // Done when every touchable node within twice that of a sphere was a candidate; else
    // they join and the state is solved again.
    const double band = kBandPerDepth * deepest;
    const bool wider = band > band_;
    band_ = band;
    if (!wider || !add_band(band)) {
      solve_boundary_forces(columns_, condensation, dofs, boundary_displacement, state);
      return state;
    }
  }
}

}  // namespace cohaptic
