// The simulation's own solve of the current state: every pressing tool at once with the
// boundary nodes held, giving the nodal forces on the contact and boundary nodes and,
// from them, the displacement of any row node (for obstacle collisions and display).
//
// f_Z follows from the condensed compliance of the pressing triangles' dofs Z with B
// held (contact_solve.h), then f_B = L_BB^-1 (u_B - L_BZ f_Z), and u_N = L_NZ f_Z + L_NB f_B.
// Loads applied to the body at given dofs P (another body pressing on it: an FEM pair's
// pushes, fem_pair_interaction.h) add F_P: Z's unloaded displacement becomes
// L_ZP F_P + Z_C^T (u_B - L_BP F_P), f_B = L_BB^-1 (u_B - L_BP F_P - L_BZ f_Z), and
// u_N = L_NZ f_Z + L_NB f_B + L_NP F_P.
// Units: m, N.
#pragma once

#include <Eigen/Core>
#include <array>
#include <span>
#include <vector>

#include "common/condense/incremental_condensation.h"
#include "common/fem/compliance.h"
#include "common/scene/scene.h"

namespace cohaptic {

struct PressingContact {
  std::array<int, 3> nodes{};  ///< volume node indices of the triangle
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();
  Eigen::Vector3d displacement = Eigen::Vector3d::Zero();  ///< d [m]
};

/// Nodal loads applied to the body (not a tool's, not a held node's) [N].
struct AppliedLoads {
  std::vector<int> dofs;   ///< global free dofs of row nodes, each once
  Eigen::VectorXd forces;  ///< one per dof [N]
};

struct StateSolution {
  std::vector<int> contact_dofs;             ///< global free dofs of the pressing triangles
  Eigen::VectorXd contact_forces;            ///< tools' forces on those dofs [N]
  std::vector<int> boundary_dofs;            ///< global free dofs of B
  Eigen::VectorXd boundary_forces;           ///< holding forces on those dofs [N]
  std::vector<Eigen::Vector3d> tool_forces;  ///< force each tool applies to the object [N]
  AppliedLoads applied;                      ///< the loads the solve was given
};

/// At most kMaxUsers contacts, sharing no node. u_B over the free dofs of B in the
/// condensation's order; `applied` on any row nodes. Throws NumericalError if a system is not
/// positive definite.
StateSolution solve_state(ComplianceColumns& columns, IncrementalCondensation& condensation,
                          const DofMap& dofs, std::span<const PressingContact> contacts,
                          const Eigen::VectorXd& boundary_displacement, ContactModel contact_model,
                          const AppliedLoads& applied = {});

/// Completes `state` from its contact forces: the holding forces on B, from
/// L_BB f_B = u_B - L_BZ f_Z - L_BP F_P (F_P: state.applied; sets state.boundary_dofs and
/// state.boundary_forces).
void solve_boundary_forces(ComplianceColumns& columns, const IncrementalCondensation& condensation,
                           const DofMap& dofs, const Eigen::VectorXd& boundary_displacement,
                           StateSolution& state);

/// Displacement [m] of `nodes` (row nodes of `columns`) in the solved state, one column each.
Eigen::Matrix3Xd displacement_of_nodes(ComplianceColumns& columns, const StateSolution& state,
                                       std::span<const int> nodes);

}  // namespace cohaptic
