// Structured tetrahedral mesh of an axis-aligned box.
//
// Each of the nx*ny*nz cells is split into six tetrahedra around its main diagonal
// (Kuhn/Freudenthal subdivision), which is conforming across cells without alternation.
// Nodes are numbered x fastest, then y, then z; tags are index + 1. Units: whatever the
// caller passes (metres inside cohaptic). A 130 mm cube with 11 divisions gives
// 1,728 nodes and 7,986 tetrahedra, close to the paper's 1,812 and 8,324.
// Grading: along each axis every cell is `grading` times the one before it (from the
// min corner towards the max), so fine cells gather where a contact is studied and coarse
// ones fill the far field; 1 is uniform, below 1 the cells shrink towards the max side.
// `uniform_cells` per axis: that many equal cells on the fine side before the growth
// starts (a uniformly fine core under a contact; 0 or 1: growth from the first cell).
#pragma once

#include <Eigen/Core>

#include "common/mesh/tet_mesh.h"

namespace cohaptic {

/// Box [min_corner, min_corner + size] with `divisions` cells along each axis (each >= 1),
/// graded by `grading` (each > 0) per axis after `uniform_cells` (each from 0 to the divisions).
TetMesh make_box_mesh(const Eigen::Vector3d& min_corner, const Eigen::Vector3d& size,
                      const Eigen::Vector3i& divisions,
                      const Eigen::Vector3d& grading = Eigen::Vector3d::Ones(),
                      const Eigen::Vector3i& uniform_cells = Eigen::Vector3i::Zero());

}  // namespace cohaptic
