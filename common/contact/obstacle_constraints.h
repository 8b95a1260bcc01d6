// The rigid obstacles' constraints on a body's surface nodes under the sphere contact model
// (sphere_contact.h): for each surface node, the nearest obstacle's linear constraint at
// rest, g + m . u >= 0, with g the node's signed distance to it and m its unit normal at the
// closest point (towards the allowed side). Units: m.
#pragma once

#include <span>
#include <vector>

#include "common/contact/obstacle.h"
#include "common/contact/obstacle_distance.h"
#include "common/contact/sphere_contact.h"
#include "common/fem/dof_map.h"
#include "common/mesh/boundary_surface.h"
#include "common/mesh/tet_mesh.h"

namespace cohaptic {

/// One per volume node: the constraint of the nearest of `obstacles` on each surface node
/// (tool -1, obstacle its index); obstacle -1 for every other node, for all without
/// obstacles, and for a node the obstacle's normal cannot hold (holdable, sphere_contact.h).
std::vector<SphereConstraint> obstacle_constraints(const TetMesh& mesh,
                                                   const BoundarySurface& surface,
                                                   const DofMap& dofs,
                                                   std::span<const ObstacleDistance> obstacles);

/// The same from the obstacles as compiled, their allowed side decided by the surface's
/// rest nodes (ObstacleDistance). Throws Error as ObstacleDistance does.
std::vector<SphereConstraint> obstacle_constraints(const TetMesh& mesh,
                                                   const BoundarySurface& surface,
                                                   const DofMap& dofs,
                                                   std::span<const Obstacle> obstacles);

/// The obstacle constraint on `node` of `constraints` (one per volume node, or empty), or
/// null if none holds it.
inline const SphereConstraint* obstacle_at(std::span<const SphereConstraint> constraints,
                                           int node) {
  if (constraints.empty()) return nullptr;
  const SphereConstraint& constraint = constraints[static_cast<std::size_t>(node)];
  return constraint.obstacle >= 0 ? &constraint : nullptr;
}

/// The rest positions of `surface`'s nodes, one column each: the reference points that decide
/// an obstacle's allowed side.
Eigen::Matrix3Xd surface_rest_points(const TetMesh& mesh, const BoundarySurface& surface);

}  // namespace cohaptic
