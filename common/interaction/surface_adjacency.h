// SurfaceAdjacency: the triangles of one body's surface and, per node, the triangles
// around it and its neighbours along surface edges. It is what the interaction between
// bodies walks: the polygons around a passive node (the collision test), the nodes next
// to a paired node (updating and adding pairs of nearest nodes).
//
// Node indices are the body's own (volume-mesh indices for an FEM body); a node on no
// triangle has empty lists. Triangles are ordered counter-clockwise seen from outside, so
// (x1 - x0) x (x2 - x0) points out of the body. Built once per body, never changed.
#pragma once

#include <span>
#include <vector>

#include "common/mesh/tet_mesh.h"

namespace cohaptic {

struct SurfaceAdjacency {
  std::vector<Triangle> triangles;
  std::vector<int> triangle_offsets;   ///< CSR, node_count + 1
  std::vector<int> triangle_list;      ///< triangles around each node
  std::vector<int> neighbour_offsets;  ///< CSR, node_count + 1
  std::vector<int> neighbour_list;     ///< nodes sharing a surface edge, ascending

  int node_count() const { return static_cast<int>(triangle_offsets.size()) - 1; }
  std::span<const int> triangles_around(int node) const {
    return slice(triangle_offsets, triangle_list, node);
  }
  std::span<const int> neighbours(int node) const {
    return slice(neighbour_offsets, neighbour_list, node);
  }

 private:
  static std::span<const int> slice(const std::vector<int>& offsets, const std::vector<int>& list,
                                    int node) {
    const auto begin = static_cast<std::size_t>(offsets[static_cast<std::size_t>(node)]);
    const auto end = static_cast<std::size_t>(offsets[static_cast<std::size_t>(node) + 1]);
    return {list.data() + begin, end - begin};
  }
};

/// Adjacency of `triangles` over nodes 0..node_count-1. Throws Error naming the triangle
/// when a node index is out of range or a triangle repeats a node.
SurfaceAdjacency make_surface_adjacency(std::vector<Triangle> triangles, int node_count);

}  // namespace cohaptic
