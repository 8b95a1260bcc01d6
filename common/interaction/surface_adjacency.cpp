#include "common/interaction/surface_adjacency.h"

#include <fmt/format.h>

#include <algorithm>

#include "common/util/error.h"

namespace cohaptic {
namespace {

// CSR from per-node lists.
void to_csr(const std::vector<std::vector<int>>& lists, std::vector<int>& offsets,
            std::vector<int>& values) {
  offsets.assign(lists.size() + 1, 0);
  for (std::size_t i = 0; i < lists.size(); ++i)
    offsets[i + 1] = offsets[i] + static_cast<int>(lists[i].size());
  values.clear();
  values.reserve(static_cast<std::size_t>(offsets.back()));
  for (const auto& list : lists) values.insert(values.end(), list.begin(), list.end());
}

}  // namespace

SurfaceAdjacency make_surface_adjacency(std::vector<Triangle> triangles, int node_count) {
  std::vector<std::vector<int>> around(static_cast<std::size_t>(node_count));
  std::vector<std::vector<int>> next(static_cast<std::size_t>(node_count));
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Triangle& tri = triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (tri[k] < 0 || tri[k] >= node_count)
        throw Error(fmt::format("surface triangle {} names node {}, outside 0..{}", t, tri[k],
                                node_count - 1));
      if (tri[k] == tri[(k + 1) % 3])
        throw Error(fmt::format("surface triangle {} repeats node {}", t, tri[k]));
    }
    for (int k = 0; k < 3; ++k) {
      const auto node = static_cast<std::size_t>(tri[k]);
      around[node].push_back(static_cast<int>(t));
      next[node].push_back(tri[(k + 1) % 3]);
      next[node].push_back(tri[(k + 2) % 3]);
    }
  }
  for (auto& list : next) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  SurfaceAdjacency adjacency;
  adjacency.triangles = std::move(triangles);
  to_csr(around, adjacency.triangle_offsets, adjacency.triangle_list);
  to_csr(next, adjacency.neighbour_offsets, adjacency.neighbour_list);
  return adjacency;
}

}  // namespace cohaptic
