// Forcible displacement of passive polygons (the several-objects paper, Sec. 2.3, Eqs. 1
// and 3): the nodes of each polygon an active node collided with are moved so that the
// active node lies on the displaced polygon, and the map from how far the targets must
// move to how the passive nodes move.
//
// A collision asks sum_k w_k (x_k + u_k) = P for its polygon's nodes x_k, target weights
// w and active node P, i.e. sum_k w_k u_k = P - T (the gap). One polygon alone: the paper's
// balance rule, u_k = w_k / (w_0^2 + w_1^2 + w_2^2) (P - T), the smallest displacement that
// puts P on it (the target moves by exactly the gap, the node nearest T the most). Several
// collisions sharing nodes: the smallest displacement of all their nodes that meets every
// condition at once (least squares where two conditions contradict, e.g. two active nodes
// asking one point of a polygon to be in two places). A fixed axis of a passive node does
// not move; a polygon fixed along an axis at all three nodes cannot give way along it, and
// that component of the gap stays (the active node meets a rigid face there).
// Each axis is a problem of its own; the displacement is linear in the gaps:
// u = map * gaps, which is what makes the linear backing of linear_backing.h exact.
// Units: metres. Positions the targets were found on are the passive body's rest
// positions when it is linear (its displacements are then totals, from rest).
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/fem/dof_map.h"
#include "common/mesh/tet_mesh.h"

namespace cohaptic {

/// One active node that collided with a passive polygon.
struct PolygonCollision {
  int pair = -1;                                      ///< index into the NodePairList
  int active = -1;                                    ///< active-body node
  Triangle polygon{};                                 ///< passive-body nodes
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();  ///< the target's, sum one
  Eigen::Vector3d target = Eigen::Vector3d::Zero();   ///< T on the undisplaced polygon [m]
  Eigen::Vector3d gap = Eigen::Vector3d::Zero();      ///< P - T [m]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();   ///< the polygon's unit outward normal
};

struct ForcibleDisplacement {
  std::vector<int> nodes;        ///< displaced passive nodes, ascending
  Eigen::MatrixXd map;           ///< 3|nodes| x 3|collisions|, node-major and axis-minor both ways
  Eigen::VectorXd displacement;  ///< 3|nodes| [m]: map * (gaps stacked)
};

/// The displacement for `collisions`; `passive_fixed_axes` per passive-body node.
ForcibleDisplacement forcible_displacement(std::span<const PolygonCollision> collisions,
                                           std::span<const AxisMask> passive_fixed_axes);

/// The gaps of `collisions` stacked (3 per collision) [m].
Eigen::VectorXd stacked_gaps(std::span<const PolygonCollision> collisions);

}  // namespace cohaptic
