// The tangent stiffness of a mass-spring network's springs at some positions: each spring
// (a, b) of stiffness k and rest length l0, now of length |l| along the unit n = l / |l|,
// adds K_s = k [n n^T + (1 - l0/|l|) (I - n n^T)] to the blocks (a, a) and (b, b) and -K_s to
// (a, b) and (b, a), so K du is minus the change of the springs' forces for a small move du
// (f = -K du on the nodes). At the rest positions every spring has its rest length and K is
// the network linearised about rest (k n n^T per spring): symmetric, positive semidefinite,
// its null space the rigid motions (and any mechanism of the network). Used where the
// network's static answer is wanted (the pushing test, the nonlinear equilibrium), not by its
// dynamics, which keep the full spring law (internal_forces.h). Units: N/m; 3 rows per node,
// node-major.
#pragma once

#include <Eigen/Core>
#include <span>

#include "common/fem/assemble_stiffness.h"
#include "common/mass_spring/mass_spring_network.h"

namespace cohaptic {

/// K over the 3 |positions| dofs of the network's nodes at `positions` (its rest positions:
/// the linearised network).
SparseMatrix network_stiffness(const Eigen::Ref<const Eigen::Matrix3Xd>& positions,
                               std::span<const Spring> springs);

}  // namespace cohaptic
