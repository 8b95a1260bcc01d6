// The simulation's own solve of the state under the sphere contact model
// (common/contact/sphere_contact.h): every sphere at once with the boundary nodes B held.
//
// Every touchable node (less B) is a candidate of its nearest sphere. A working set of them
// is condensed with B held (M_CC, M_CB from the incremental condensation); its compliance
// L~ = M_CC^-1 and free displacement u0 = -L~ M_CB u_B give the unilateral problem over its
// normal pushes (unilateral_contact_solve.h), and then f_B and any node's displacement as for
// the other models (state_solve.h). The set starts as the nodes the spheres hold at rest;
// every other candidate that the solved state carries into its sphere joins it, until none
// does: the answer over all candidates. Units: m, N.
#pragma once

#include <Eigen/Core>
#include <span>

#include "common/contact/sphere_contact.h"
#include "common/sim/state_solve.h"
#include "common/mesh/tet_mesh.h"

namespace cohaptic {

/// `candidates`: the nodes the spheres may hold (the touchable triangles' nodes); u_B over
/// the free dofs of B in the condensation's order. contact_dofs are the free dofs of the
/// final working set (zero force where released); tool_forces[t] is sphere t's force on the
/// object. Throws NumericalError if the problem cannot be solved.
StateSolution solve_sphere_state(ComplianceColumns& columns, IncrementalCondensation& condensation, const TetMesh& mesh,
                                 const DofMap& dofs, std::span<const int> candidates, std::span<const SphereTool> spheres,
                                 const Eigen::VectorXd& boundary_displacement);

}  // namespace cohaptic
