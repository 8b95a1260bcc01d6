#include "common/contact/segment_triangle_crossing.h"

#include <Eigen/Geometry>
#include <cmath>

namespace cohaptic {

std::optional<SegmentTriangleCrossing> segment_triangle_crossing(
    const Eigen::Vector3d& from, const Eigen::Vector3d& to, const Eigen::Vector3d& a,
    const Eigen::Vector3d& b, const Eigen::Vector3d& c) noexcept {
  // Moeller and Trumbore: solve from + t d = a + s (b - a) + r (c - a) by Cramer's rule.
  const Eigen::Vector3d d = to - from;
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d p = d.cross(e2);
  const double det = e1.dot(p);
  // Parallel to the plane (relative to the sizes involved) or a degenerate triangle.
  const double scale = d.norm() * e1.norm() * e2.norm();
  if (!(std::abs(det) > 1e-12 * scale)) return std::nullopt;
  const double inv = 1.0 / det;
  const Eigen::Vector3d s = from - a;
  const double u = s.dot(p) * inv;
  if (u < 0 || u > 1) return std::nullopt;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = d.dot(q) * inv;
  if (v < 0 || u + v > 1) return std::nullopt;
  const double t = e2.dot(q) * inv;
  if (t < 0 || t > 1) return std::nullopt;
  return SegmentTriangleCrossing{t, Eigen::Vector3d(1 - u - v, u, v)};
}

}  // namespace cohaptic
