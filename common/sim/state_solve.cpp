#include "common/sim/state_solve.h"

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include "common/condense/dof_blocks.h"
#include "common/ir/contact_solve.h"
#include "common/sim/loaded_columns.h"
#include "common/util/error.h"

namespace cohaptic {

StateSolution solve_state(ComplianceColumns& columns, IncrementalCondensation& condensation,
                          const DofMap& dofs, std::span<const PressingContact> contacts,
                          const Eigen::VectorXd& boundary_displacement, ContactModel contact_model,
                          const AppliedLoads& applied) {
  if (static_cast<int>(contacts.size()) > kMaxUsers)
    throw Error(
        fmt::format("solve_state: {} pressing tools, at most {}", contacts.size(), kMaxUsers));
  StateSolution state;
  state.tool_forces.assign(contacts.size(), Eigen::Vector3d::Zero());
  state.applied = applied;

  std::vector<int> nodes;
  std::vector<ContactDof> contact_dofs;
  std::vector<Eigen::Vector3d> displacement;
  for (std::size_t t = 0; t < contacts.size(); ++t) {
    displacement.push_back(contacts[t].displacement);
    for (int i = 0; i < 3; ++i) {
      nodes.push_back(contacts[t].nodes[i]);
      for (int axis = 0; axis < 3; ++axis)
        if (!dofs.is_fixed(contacts[t].nodes[i], axis)) {
          state.contact_dofs.push_back(3 * contacts[t].nodes[i] + axis);
          contact_dofs.push_back({static_cast<int>(t), axis, contacts[t].weights[i]});
        }
    }
  }
  state.contact_forces =
      Eigen::VectorXd::Zero(static_cast<Eigen::Index>(state.contact_dofs.size()));
  if (!nodes.empty()) {
    const CondensedOperator op = condensation.condense(nodes);
    const Eigen::LLT<Eigen::MatrixXd> llt(op.m_cc);
    const SmallMatrix compliance =
        llt.solve(Eigen::MatrixXd::Identity(op.m_cc.rows(), op.m_cc.cols()));
    // Z's displacement unloaded by the tools: -L~ M_CB u_B = Z_C^T u_B; the applied loads
    // add L_ZP F_P and move B's held displacement relative to them by -L_BP F_P.
    SmallVector free_displacement;
    if (applied.dofs.empty()) {
      free_displacement = -compliance * (op.m_cb * boundary_displacement);
    } else {
      const std::vector<int> boundary_dofs =
          free_dofs_of_nodes(dofs, condensation.boundary_nodes());
      const Eigen::VectorXd boundary_load =
          gather_compliance(columns, boundary_dofs, applied.dofs) * applied.forces;
      free_displacement =
          -compliance * (op.m_cb * (boundary_displacement - boundary_load)) +
          gather_compliance(columns, state.contact_dofs, applied.dofs) * applied.forces;
    }
    SmallVector nodal;
    if (!solve_contact_forces(contact_model, compliance, free_displacement, contact_dofs,
                              displacement, nodal, state.tool_forces))
      throw NumericalError("the state's contact system is not positive definite");
    state.contact_forces = nodal;
  }
  solve_boundary_forces(columns, condensation, dofs, boundary_displacement, state);
  return state;
}

void solve_boundary_forces(ComplianceColumns& columns, const IncrementalCondensation& condensation,
                           const DofMap& dofs, const Eigen::VectorXd& boundary_displacement,
                           StateSolution& state) {
  state.boundary_dofs = free_dofs_of_nodes(dofs, condensation.boundary_nodes());
  Eigen::VectorXd rhs = boundary_displacement;
  if (!state.applied.dofs.empty() && !state.boundary_dofs.empty())
    rhs -=
        gather_compliance(columns, state.boundary_dofs, state.applied.dofs) * state.applied.forces;
  if (!state.contact_dofs.empty())
    rhs -=
        gather_compliance(columns, state.boundary_dofs, state.contact_dofs) * state.contact_forces;
  state.boundary_forces = condensation.solve_boundary(rhs);
}

Eigen::Matrix3Xd displacement_of_nodes(ComplianceColumns& columns, const StateSolution& state,
                                       std::span<const int> nodes) {
  std::vector<int> positions(nodes.size());
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    positions[k] = columns.row_position(nodes[k]);
    if (positions[k] < 0)
      throw Error(fmt::format(
          "compliance rows are not kept for node {} (not touchable or on the surface)", nodes[k]));
  }
  return displacement_of_rows(loaded_columns(columns, state), positions);
}

}  // namespace cohaptic
