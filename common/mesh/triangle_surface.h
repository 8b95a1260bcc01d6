// TriangleSurface: a standalone triangle surface (an obstacle such as the inner skull,
// or a surface read from a FreeSurfer file before it is remeshed into tetrahedra).
//
// Units: metres once loaded through a scene; readers return file coordinates.
// Triangles are 0-based vertex indices; orientation is whatever the source had.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "common/mesh/tet_mesh.h"

namespace cohaptic {

struct TriangleSurface {
  Eigen::Matrix3Xd vertices;        ///< one column per vertex
  std::vector<Triangle> triangles;  ///< 0-based vertex indices

  int vertex_count() const { return static_cast<int>(vertices.cols()); }
  int triangle_count() const { return static_cast<int>(triangles.size()); }
};

}  // namespace cohaptic
