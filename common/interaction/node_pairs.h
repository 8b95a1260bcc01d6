// Pairs of nearest nodes across two bodies (the several-objects paper, Sec. 2.1 and 2.5):
// every step each active node of the front body is tested against the polygons around the
// passive node it is paired with on the body behind it.
//
// The list is made once by brute force (before the first step); each step the pairs are
// updated by walking each passive node along its surface to a neighbour nearer the
// active node, until none is nearer (a surface moves little per step, so the walk is a few
// hops); when a pair collides, the active node's surface neighbours that are not yet
// paired join the list (Sec. 2.5), paired by walking from the colliding passive node.
// An active node is in at most one pair. Node indices are each body's own; positions in
// metres, one column per node of that body. The per-step functions allocate nothing while
// the list stays within the capacity make_node_pairs reserves (every active-body node).
#pragma once

#include <span>
#include <vector>

#include "common/interaction/node_polygon_collision.h"
#include "common/interaction/surface_adjacency.h"

namespace cohaptic {

struct NodePair {
  int active = -1;   ///< node of the front (active) body
  int passive = -1;  ///< node of the behind (passive) body
};

struct NodePairList {
  std::vector<NodePair> pairs;
  std::vector<char> paired;  ///< per active-body node: 1 when in a pair
};

/// Pairs each of `active_nodes` with the nearest of `passive_nodes` (brute force).
NodePairList make_node_pairs(std::span<const int> active_nodes,
                             const NodePositions& active_positions,
                             std::span<const int> passive_nodes,
                             const NodePositions& passive_positions);

/// From `start`, the surface neighbour nearer `point` while there is one: a local nearest.
int walk_to_nearest_node(const Eigen::Vector3d& point, int start,
                         const NodePositions& passive_positions,
                         const SurfaceAdjacency& passive_surface) noexcept;

/// Update of pairs: every passive node walked to its local nearest. Returns how many changed.
int update_node_pairs(NodePairList& list, const NodePositions& active_positions,
                      const NodePositions& passive_positions,
                      const SurfaceAdjacency& passive_surface) noexcept;

/// Addition of pairs: the surface neighbours of the active node of each pair in
/// `colliding` (indices into list.pairs) that are not yet paired. Returns how many joined.
int add_neighbour_pairs(NodePairList& list, std::span<const int> colliding,
                        const NodePositions& active_positions,
                        const SurfaceAdjacency& active_surface,
                        const NodePositions& passive_positions,
                        const SurfaceAdjacency& passive_surface);

}  // namespace cohaptic
