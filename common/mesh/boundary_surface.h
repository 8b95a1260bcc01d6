// BoundarySurface: the outer surface of a TetMesh, the part a tool can touch.
//
// Triangles are faces that belong to exactly one tetrahedron, ordered counter-clockwise
// seen from outside, so (x1-x0) x (x2-x0) is the outward normal. Node indices are those of
// the volume mesh. node_triangles(i) lists the surface triangles around volume node i
// (empty for interior nodes). triangle_neighbours gives edge adjacency for walking the
// surface (contact patches, pseudo-normals).
#pragma once

#include <span>
#include <vector>

#include "common/mesh/tet_mesh.h"

namespace cohaptic {

struct BoundarySurface {
  std::vector<Triangle> triangles;  ///< outward-oriented, volume node indices
  std::vector<int> triangle_tet;    ///< the tetrahedron each triangle is a face of
  /// Per triangle, the triangle across edge k = (v_k, v_k+1), or -1 where the edge is
  /// not shared by exactly two consistently oriented triangles (a non-manifold edge).
  std::vector<std::array<int, 3>> triangle_neighbours;
  std::vector<int> nodes;                  ///< sorted volume node indices on the surface
  std::vector<int> node_triangle_offsets;  ///< CSR offsets, size node_count + 1
  std::vector<int> node_triangle_list;     ///< CSR values: triangle indices

  int triangle_count() const { return static_cast<int>(triangles.size()); }

  /// Surface triangles incident to volume node `node`.
  std::span<const int> node_triangles(int node) const {
    const int begin = node_triangle_offsets[static_cast<std::size_t>(node)];
    const int end = node_triangle_offsets[static_cast<std::size_t>(node) + 1];
    return {node_triangle_list.data() + begin, static_cast<std::size_t>(end - begin)};
  }
};

/// Extracts the boundary of `mesh` (tetrahedra must be positively oriented).
/// Throws MeshError naming the face if a face is shared by more than two tetrahedra.
BoundarySurface extract_boundary_surface(const TetMesh& mesh);

/// Edge neighbours of consistently oriented triangles (see BoundarySurface::triangle_neighbours).
std::vector<std::array<int, 3>> triangle_edge_neighbours(const std::vector<Triangle>& triangles);

/// Unit outward normal of surface triangle `tri` at rest.
Eigen::Vector3d triangle_normal(const TetMesh& mesh, const Triangle& tri);

}  // namespace cohaptic
