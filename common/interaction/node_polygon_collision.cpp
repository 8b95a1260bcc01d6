#include "common/interaction/node_polygon_collision.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace cohaptic {
namespace {

Eigen::Vector3d corner(const NodePositions& positions, const Triangle& triangle, int k) {
  return positions.col(triangle[static_cast<std::size_t>(k)]);
}

// Twice the signed area of (p, q, r) along the unit normal n.
double doubled_area(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r,
                    const Eigen::Vector3d& n) {
  return (q - p).cross(r - p).dot(n);
}

}  // namespace

bool instant_collision_test(const Eigen::Vector3d& active, int passive_node,
                            const NodePositions& passive_positions,
                            const SurfaceAdjacency& passive_surface) noexcept {
  const auto around = passive_surface.triangles_around(passive_node);
  if (around.empty()) return false;
  const Eigen::Vector3d passive = passive_positions.col(passive_node);
  for (const int t : around) {
    const Triangle& tri = passive_surface.triangles[static_cast<std::size_t>(t)];
    const Eigen::Vector3d a = corner(passive_positions, tri, 0);
    const Eigen::Vector3d normal =
        (corner(passive_positions, tri, 1) - a).cross(corner(passive_positions, tri, 2) - a);
    if ((active - passive).dot(normal) > 0) return false;
  }
  return true;
}

std::optional<PolygonTarget> detailed_collision_test(
    const Eigen::Vector3d& active, int passive_node, const NodePositions& passive_positions,
    const SurfaceAdjacency& passive_surface) noexcept {
  std::optional<PolygonTarget> nearest;
  double nearest_distance = std::numeric_limits<double>::infinity();
  for (const int t : passive_surface.triangles_around(passive_node)) {
    const Triangle& tri = passive_surface.triangles[static_cast<std::size_t>(t)];
    const Eigen::Vector3d a = corner(passive_positions, tri, 0);
    const Eigen::Vector3d b = corner(passive_positions, tri, 1);
    const Eigen::Vector3d c = corner(passive_positions, tri, 2);
    const Eigen::Vector3d area_normal = (b - a).cross(c - a);
    const double doubled_triangle_area = area_normal.norm();
    if (!(doubled_triangle_area > 0)) continue;
    const Eigen::Vector3d normal = area_normal / doubled_triangle_area;
    const double height = (active - a).dot(normal);
    const double distance = std::abs(height);
    if (distance >= nearest_distance) continue;
    const Eigen::Vector3d foot = active - height * normal;
    const Eigen::Vector3d weights(doubled_area(foot, b, c, normal),
                                  doubled_area(foot, c, a, normal),
                                  doubled_area(foot, a, b, normal));
    if (weights.minCoeff() < 0) continue;
    nearest_distance = distance;
    nearest = PolygonTarget{t, weights / doubled_triangle_area, foot, normal};
  }
  return nearest;
}

std::optional<PolygonTarget> node_polygon_collision(
    const Eigen::Vector3d& active, int passive_node, const NodePositions& passive_positions,
    const SurfaceAdjacency& passive_surface) noexcept {
  if (!instant_collision_test(active, passive_node, passive_positions, passive_surface))
    return std::nullopt;
  return detailed_collision_test(active, passive_node, passive_positions, passive_surface);
}

}  // namespace cohaptic
