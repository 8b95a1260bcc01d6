#include "common/interaction/node_pairs.h"

#include <limits>

namespace cohaptic {

NodePairList make_node_pairs(std::span<const int> active_nodes,
                             const NodePositions& active_positions,
                             std::span<const int> passive_nodes,
                             const NodePositions& passive_positions) {
  NodePairList list;
  list.paired.assign(static_cast<std::size_t>(active_positions.cols()), 0);
  list.pairs.reserve(list.paired.size());
  if (passive_nodes.empty()) return list;
  for (const int active : active_nodes) {
    if (list.paired[static_cast<std::size_t>(active)]) continue;
    int nearest = passive_nodes.front();
    double nearest_squared = std::numeric_limits<double>::infinity();
    for (const int passive : passive_nodes) {
      const double squared =
          (passive_positions.col(passive) - active_positions.col(active)).squaredNorm();
      if (squared < nearest_squared) {
        nearest_squared = squared;
        nearest = passive;
      }
    }
    list.pairs.push_back({active, nearest});
    list.paired[static_cast<std::size_t>(active)] = 1;
  }
  return list;
}

int walk_to_nearest_node(const Eigen::Vector3d& point, int start,
                         const NodePositions& passive_positions,
                         const SurfaceAdjacency& passive_surface) noexcept {
  int node = start;
  double squared = (passive_positions.col(node) - point).squaredNorm();
  for (bool moved = true; moved;) {
    moved = false;
    for (const int next : passive_surface.neighbours(node)) {
      const double next_squared = (passive_positions.col(next) - point).squaredNorm();
      if (next_squared < squared) {
        squared = next_squared;
        node = next;
        moved = true;
      }
    }
  }
  return node;
}

int update_node_pairs(NodePairList& list, const NodePositions& active_positions,
                      const NodePositions& passive_positions,
                      const SurfaceAdjacency& passive_surface) noexcept {
  int changed = 0;
  for (NodePair& pair : list.pairs) {
    const int nearest = walk_to_nearest_node(active_positions.col(pair.active), pair.passive,
                                             passive_positions, passive_surface);
    changed += nearest != pair.passive;
    pair.passive = nearest;
  }
  return changed;
}

int add_neighbour_pairs(NodePairList& list, std::span<const int> colliding,
                        const NodePositions& active_positions,
                        const SurfaceAdjacency& active_surface,
                        const NodePositions& passive_positions,
                        const SurfaceAdjacency& passive_surface) {
  int added = 0;
  for (const int index : colliding) {
    // By value: push_back below may move the list's storage.
    const NodePair pair = list.pairs[static_cast<std::size_t>(index)];
    for (const int neighbour : active_surface.neighbours(pair.active)) {
      char& paired = list.paired[static_cast<std::size_t>(neighbour)];
      if (paired) continue;
      paired = 1;
      list.pairs.push_back(
          {neighbour, walk_to_nearest_node(active_positions.col(neighbour), pair.passive,
                                           passive_positions, passive_surface)});
      ++added;
    }
  }
  return added;
}

}  // namespace cohaptic
