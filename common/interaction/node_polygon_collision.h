// The node-polygon collision test of the several-objects paper (Sec. 2.3): does an active
// node of one body collide with the polygons around its paired passive node of another,
// and where on them is its target point?
//
// 1. Instant test, the paper's Eq. (0): (P_active - P_passive) . N_i <= 0 for every
//    polygon S_i around the passive node (N_i its outward normal): the active node lies
//    behind every plane through the passive node's polygons. Otherwise: no collision.
// 2. Detailed test: the foot F_i of the perpendicular from the active node to the plane of
//    each S_i; no collision unless some foot lies inside its polygon (on the edge counts).
// 3. Target point T: the point of those polygons nearest the active node. With one
//    polygon as the Lagrange constraint, min |T - P| subject to N . (T - X) = 0 gives the
//    foot itself; of several polygons with a foot inside, the nearest foot is taken.
// The weights of T are the paper's alpha : beta : gamma = area(TBC) : area(TCA) : area(TAB)
// over the polygon's nodes (A, B, C) = the triangle's (0, 1, 2), summing to one.
// Polygons are triangles; degenerate ones (no area) never hold a foot. Positions in metres,
// one column per node of the passive body, usually its rest positions (see
// forcible_displacement.h). Allocation-free.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "common/interaction/surface_adjacency.h"

namespace cohaptic {

using NodePositions = Eigen::Ref<const Eigen::Matrix3Xd>;

struct PolygonTarget {
  int triangle = -1;                                  ///< index into SurfaceAdjacency::triangles
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();  ///< T = sum_k weights[k] x(triangle[k])
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    ///< T [m]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();   ///< the polygon's unit outward normal
};

/// Eq. (0) for `active` against the polygons around `passive_node`; false when the node is
/// on no polygon.
bool instant_collision_test(const Eigen::Vector3d& active, int passive_node,
                            const NodePositions& passive_positions,
                            const SurfaceAdjacency& passive_surface) noexcept;

/// The detailed test and the target point: empty when no foot of the perpendicular from
/// `active` falls inside a polygon around `passive_node`.
std::optional<PolygonTarget> detailed_collision_test(
    const Eigen::Vector3d& active, int passive_node, const NodePositions& passive_positions,
    const SurfaceAdjacency& passive_surface) noexcept;

/// Both tests in the paper's order: the target point, or empty when there is no collision.
std::optional<PolygonTarget> node_polygon_collision(
    const Eigen::Vector3d& active, int passive_node, const NodePositions& passive_positions,
    const SurfaceAdjacency& passive_surface) noexcept;

}  // namespace cohaptic
