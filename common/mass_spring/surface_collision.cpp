#include "common/mass_spring/surface_collision.h"

#include <Eigen/Geometry>

#include <limits>

namespace cohaptic {
namespace {

Eigen::Vector3d closest_point_on_edge(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                      const Eigen::Vector3d& b) {
  const Eigen::Vector3d edge = b - a;
  const double length2 = edge.squaredNorm();
  if (!(length2 > 0)) return a;
  const double t = (p - a).dot(edge) / length2;
  if (t <= 0) return a;
  if (t >= 1) return b;
  return a + t * edge;
}

}  // namespace

Eigen::Vector3d closest_point_on_face(const Eigen::Vector3d& p, const Eigen::Vector3d& sn,
                                      const Eigen::Vector3d& b, const Eigen::Vector3d& c) noexcept {
  const Eigen::Vector3d normal = (b - sn).cross(c - sn);
  const double area2 = normal.squaredNorm();
  if (area2 > 0) {
    const Eigen::Vector3d foot = p - (p - sn).dot(normal) / area2 * normal;
    const bool inside = (b - sn).cross(foot - sn).dot((b - sn).cross(c - sn)) > 0 &&
                        (c - sn).cross(foot - sn).dot((c - sn).cross(b - sn)) > 0 &&
                        (b - c).cross(foot - c).dot((b - c).cross(sn - c)) > 0;  // Eq. (4)
    if (inside) return foot;
  }
  Eigen::Vector3d best = closest_point_on_edge(p, sn, b);
  for (const Eigen::Vector3d& candidate :
       {closest_point_on_edge(p, b, c), closest_point_on_edge(p, c, sn)})
    if ((candidate - p).squaredNorm() < (best - p).squaredNorm()) best = candidate;
  return best;
}

SurfaceContact find_surface_contact(const MassSpringNetwork& network, const Eigen::Matrix3Xd& x,
                                    const Eigen::Vector3d& tool, double radius) noexcept {
  SurfaceContact contact;
  double nearest2 = std::numeric_limits<double>::infinity();
  for (int node : network.surface_nodes) {
    const double d2 = (x.col(node) - tool).squaredNorm();
    if (d2 < nearest2) {
      nearest2 = d2;
      contact.nearest_node = node;
    }
  }
  if (contact.nearest_node < 0) return contact;
  const int sn = contact.nearest_node;
  double best2 = std::numeric_limits<double>::infinity();
  for (int i = network.node_triangle_start[static_cast<std::size_t>(sn)];
       i < network.node_triangle_start[static_cast<std::size_t>(sn) + 1]; ++i) {
    const int t = network.node_triangles[static_cast<std::size_t>(i)];
    const auto& tri = network.triangles[static_cast<std::size_t>(t)];
    // The triangle's corners in order starting at s_n (keeps the orientation).
    const int at = tri[0] == sn ? 0 : tri[1] == sn ? 1 : 2;
    const Eigen::Vector3d a = x.col(tri[static_cast<std::size_t>(at)]);
    const Eigen::Vector3d b = x.col(tri[static_cast<std::size_t>((at + 1) % 3)]);
    const Eigen::Vector3d c = x.col(tri[static_cast<std::size_t>((at + 2) % 3)]);
    const Eigen::Vector3d q = closest_point_on_face(tool, a, b, c);
    const double d2 = (q - tool).squaredNorm();
    if (d2 < best2) {
      best2 = d2;
      contact.triangle = t;
      contact.point = q;
      const Eigen::Vector3d n = (b - a).cross(c - a);
      if (n.norm() > 0) contact.normal = n.normalized();
    }
  }
  if (contact.triangle < 0) return contact;
  contact.depth = (contact.point - tool).dot(contact.normal) + radius;
  contact.colliding = contact.depth >= 0;
  return contact;
}

}  // namespace cohaptic
