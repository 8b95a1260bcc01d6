// The stiffness of a mass-spring network linearised about its rest positions: each spring
// (a, b) of stiffness k along the unit rest direction n adds k n n^T to the blocks (a, a)
// and (b, b) and -k n n^T to (a, b) and (b, a), so K u is the springs' force for small
// displacements u from rest (f = -K u on the nodes). Symmetric, positive semidefinite; its
// null space holds the rigid motions (and any mechanism of the network). Used where the
// network's static answer is wanted (the pushing test), not by its dynamics, which keep
// the full spring law (internal_forces.h). Units: N/m; 3 rows per node, node-major.
#pragma once

#include <Eigen/Core>
#include <span>

#include "common/fem/assemble_stiffness.h"
#include "common/mass_spring/mass_spring_network.h"

namespace cohaptic {

/// K over the 3 |positions| dofs of the network's nodes (`positions` its rest ones).
SparseMatrix network_stiffness(const Eigen::Ref<const Eigen::Matrix3Xd>& positions, std::span<const Spring> springs);

}  // namespace cohaptic
