#include "common/contact/obstacle_constraints.h"

#include <limits>

namespace cohaptic {

std::vector<SphereConstraint> obstacle_constraints(const TetMesh& mesh, const BoundarySurface& surface,
                                                   const DofMap& dofs, std::span<const ObstacleDistance> obstacles) {
  SphereConstraint none;
  none.gap = std::numeric_limits<double>::infinity();
  std::vector<SphereConstraint> constraints(static_cast<std::size_t>(mesh.node_count()), none);
  for (int node : surface.nodes) {
    SphereConstraint& constraint = constraints[static_cast<std::size_t>(node)];
    for (int o = 0; o < static_cast<int>(obstacles.size()); ++o) {
      const ObstaclePoint nearest = obstacles[static_cast<std::size_t>(o)].closest_point(mesh.nodes.col(node));
      if (!(nearest.signed_distance < constraint.gap)) continue;
      constraint.gap = nearest.signed_distance;
      constraint.normal = nearest.normal;
      constraint.obstacle = o;
    }
    if (constraint.obstacle >= 0 && !holdable(constraint.normal, dofs.fixed_axes[static_cast<std::size_t>(node)]))
      constraint = none;
  }
  return constraints;
}

std::vector<SphereConstraint> obstacle_constraints(const TetMesh& mesh, const BoundarySurface& surface,
                                                   const DofMap& dofs, std::span<const Obstacle> obstacles) {
  const Eigen::Matrix3Xd rest = surface_rest_points(mesh, surface);
  std::vector<ObstacleDistance> distances;
  for (const Obstacle& obstacle : obstacles) distances.emplace_back(obstacle, rest);
  return obstacle_constraints(mesh, surface, dofs, distances);
}

Eigen::Matrix3Xd surface_rest_points(const TetMesh& mesh, const BoundarySurface& surface) {
  Eigen::Matrix3Xd points(3, static_cast<Eigen::Index>(surface.nodes.size()));
  for (std::size_t i = 0; i < surface.nodes.size(); ++i)
    points.col(static_cast<Eigen::Index>(i)) = mesh.nodes.col(surface.nodes[i]);
  return points;
}

}  // namespace cohaptic
