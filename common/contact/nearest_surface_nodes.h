// The step-delay boundary set of the paper's T150/T300 conditions: the N surface nodes
// nearest the contact region, to be held at their current displacement.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/fem/dof_map.h"
#include "common/mesh/boundary_surface.h"
#include "common/mesh/tet_mesh.h"

namespace cohaptic {

/// The `count` surface nodes nearest any of `points` [m], nearest first, skipping fully
/// fixed nodes and nodes marked in `excluded` (per volume node; may be empty). Throws
/// Error if the surface has fewer such nodes.
std::vector<int> nearest_surface_nodes(const TetMesh& mesh, const BoundarySurface& surface,
                                       const DofMap& dofs, std::span<const Eigen::Vector3d> points,
                                       int count, const std::vector<bool>& excluded);

}  // namespace cohaptic
