#include "common/separation/interface_regions.h"

#include <Eigen/Geometry>
#include <algorithm>

namespace cohaptic {

NodeRegions node_regions(const std::vector<Triangle>& triangles, int node_count) {
  NodeRegions regions;
  regions.offsets.assign(static_cast<std::size_t>(node_count) + 1, 0);
  for (const Triangle& t : triangles)
    for (int node : t) ++regions.offsets[node + 1];
  for (int n = 0; n < node_count; ++n) regions.offsets[n + 1] += regions.offsets[n];
  regions.triangles.resize(static_cast<std::size_t>(regions.offsets.back()));
  std::vector<int> fill(regions.offsets.begin(), regions.offsets.end() - 1);
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t)
    for (int node : triangles[t]) regions.triangles[fill[node]++] = t;
  return regions;
}

Eigen::Vector3d region_normal(const Eigen::Matrix3Xd& positions,
                              const std::vector<Triangle>& triangles, std::span<const int> region) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int t : region) {
    const Triangle& tri = triangles[t];
    const Eigen::Vector3d a = positions.col(tri[0]);
    sum += (positions.col(tri[1]) - a)
               .cross(positions.col(tri[2]) - a);  // twice the area along the normal
  }
  return sum.normalized();
}

std::vector<int> nodes_released_with(const NodeRegions& regions,
                                     const std::vector<Triangle>& triangles, int node) {
  const std::span<const int> released = regions.of(node);
  const auto is_released = [&](int t) {
    return std::binary_search(released.begin(), released.end(), t);
  };
  std::vector<int> nodes;
  for (int t : released)
    for (int candidate : triangles[t]) {
      if (std::find(nodes.begin(), nodes.end(), candidate) != nodes.end()) continue;
      const std::span<const int> own = regions.of(candidate);
      if (std::all_of(own.begin(), own.end(), is_released)) nodes.push_back(candidate);
    }
  std::sort(nodes.begin(), nodes.end());
  return nodes;
}

}  // namespace cohaptic
