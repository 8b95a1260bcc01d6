// The regions D_n of the separation-forces paper (Sec. IV): the interface triangles around
// each interface node, as compressed lists, and the nodes a local separation releases.
//
// D_n is what the locally separated field of node n releases; a node is released when
// every interface triangle it belongs to is released (a node inside D_n on the rim of D_n
// keeps its other triangles and stays tied).
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/mesh/tet_mesh.h"

namespace cohaptic {

struct NodeRegions {
  std::vector<int> offsets;    ///< per node + 1
  std::vector<int> triangles;  ///< triangle indices, ascending within each node

  std::span<const int> of(int node) const {
    const auto n = static_cast<std::size_t>(node);
    return {triangles.data() + offsets[n], static_cast<std::size_t>(offsets[n + 1] - offsets[n])};
  }
  int node_count() const { return static_cast<int>(offsets.size()) - 1; }
};

NodeRegions node_regions(const std::vector<Triangle>& triangles, int node_count);

/// The unit normal of a region: the area-weighted mean of its triangles' normals
/// ((p1 - p0) x (p2 - p0) directions).
Eigen::Vector3d region_normal(const Eigen::Matrix3Xd& positions,
                              const std::vector<Triangle>& triangles, std::span<const int> region);

/// The nodes left without a connected triangle when the triangles of D_node are released.
std::vector<int> nodes_released_with(const NodeRegions& regions,
                                     const std::vector<Triangle>& triangles, int node);

}  // namespace cohaptic
