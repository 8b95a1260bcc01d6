// The 1-ring of every vertex of a triangle surface: the vertices it shares an edge with,
// in increasing index order, stored flat (offsets and indices) so that one vector each
// holds a whole surface. Computed once per body; the home-spring patches copy from it.
#pragma once

#include <span>
#include <vector>

#include "common/mesh/tet_mesh.h"

namespace cohaptic {

struct VertexRings {
  std::vector<int> offsets;  ///< vertex v's ring: vertices[offsets[v] .. offsets[v + 1])
  std::vector<int> vertices;

  std::span<const int> ring(int vertex) const {
    const auto begin = static_cast<std::size_t>(offsets[static_cast<std::size_t>(vertex)]);
    const auto end = static_cast<std::size_t>(offsets[static_cast<std::size_t>(vertex) + 1]);
    return std::span<const int>(vertices).subspan(begin, end - begin);
  }
};

/// Throws Error if a triangle names a vertex outside 0 .. vertex_count - 1.
VertexRings vertex_rings(std::span<const Triangle> triangles, int vertex_count);

}  // namespace cohaptic
