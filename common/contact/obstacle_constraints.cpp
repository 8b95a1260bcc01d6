#include "common/contact/obstacle_constraints.h"

#include <limits>

namespace cohaptic {

std::vector<SphereConstraint> obstacle_constraints(const TetMesh& mesh,
                                                   const BoundarySurface& surface,
                                                   const DofMap& dofs,
                                                   std::span<const ObstacleDistance> obstacles) {
  std::vector<SphereConstraint> constraints(static_cast<std::size_t>(mesh.node_count()));
  for (int node : surface.nodes) {
    SphereConstraint nearest_obstacle;
    nearest_obstacle.gap = std::numeric_limits<double>::infinity();
    for (int o = 0; o < static_cast<int>(obstacles.size()); ++o) {
      const ObstaclePoint nearest =
          obstacles[static_cast<std::size_t>(o)].closest_point(mesh.nodes.col(node));
      if (!(nearest.signed_distance < nearest_obstacle.gap)) continue;
      nearest_obstacle.gap = nearest.signed_distance;
      nearest_obstacle.normal = nearest.normal;
      nearest_obstacle.obstacle = o;
    }
    if (nearest_obstacle.obstacle >= 0 &&
        holdable(nearest_obstacle.normal, dofs.fixed_axes[static_cast<std::size_t>(node)]))
      constraints[static_cast<std::size_t>(node)] = nearest_obstacle;
  }
  return constraints;
}

std::vector<SphereConstraint> obstacle_constraints(const TetMesh& mesh,
                                                   const BoundarySurface& surface,
                                                   const DofMap& dofs,
                                                   std::span<const Obstacle> obstacles) {
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
