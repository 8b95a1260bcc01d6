#include "common/separation/laser_groove.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

namespace cohaptic {
namespace {

// A convex polygon in a plane, small enough to live on the stack: a triangle clipped by
// four half-planes has at most seven corners.
struct Polygon {
  std::array<Eigen::Vector2d, 8> corners;
  int count = 0;
};

// The part of `polygon` where (p - origin) . normal <= 0 (Sutherland–Hodgman, one edge).
Polygon clip(const Polygon& polygon, const Eigen::Vector2d& origin,
             const Eigen::Vector2d& normal) noexcept {
  Polygon out;
  for (int i = 0; i < polygon.count; ++i) {
    const Eigen::Vector2d& p = polygon.corners[i];
    const Eigen::Vector2d& q = polygon.corners[(i + 1) % polygon.count];
    const double dp = (p - origin).dot(normal), dq = (q - origin).dot(normal);
    if (dp <= 0) out.corners[out.count++] = p;
    if ((dp < 0 && dq > 0) || (dp > 0 && dq < 0))
      out.corners[out.count++] = p + dp / (dp - dq) * (q - p);
  }
  return out;
}

double polygon_area(const Polygon& polygon) noexcept {
  double twice = 0;
  for (int i = 0; i < polygon.count; ++i) {
    const Eigen::Vector2d& p = polygon.corners[i];
    const Eigen::Vector2d& q = polygon.corners[(i + 1) % polygon.count];
    twice += p.x() * q.y() - p.y() * q.x();
  }
  return 0.5 * std::abs(twice);
}

}  // namespace

double strip_area_in_triangle(const SeparationPatch& patch, int t, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b, double width) noexcept {
  const Triangle& tri = patch.triangles[t];
  const Eigen::Vector3d origin = patch.positions.col(tri[0]);
  const Eigen::Vector3d e1 = (patch.positions.col(tri[1]) - origin).normalized();
  const Eigen::Vector3d e2 = patch.normals[t].cross(e1);
  const auto in_plane = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d((p - origin).dot(e1), (p - origin).dot(e2));
  };
  const Eigen::Vector2d pa = in_plane(a), pb = in_plane(b);
  const double length = (pb - pa).norm();
  if (!(length > 0)) return 0;
  const Eigen::Vector2d along = (pb - pa) / length;
  const Eigen::Vector2d across(-along.y(), along.x());
  Polygon polygon;
  for (int k = 0; k < 3; ++k)
    polygon.corners[polygon.count++] = in_plane(patch.positions.col(tri[k]));
  polygon = clip(polygon, pa, -along);
  polygon = clip(polygon, pb, along);
  polygon = clip(polygon, pa + 0.5 * width * across, across);
  polygon = clip(polygon, pa - 0.5 * width * across, -across);
  return polygon.count >= 3 ? polygon_area(polygon) : 0.0;
}

LaserSample step_laser(const SeparationPatch& patch, SeparationState& state, LaserFibre& fibre,
                       const Eigen::Vector3d& tip, bool on, double dt) noexcept {
  LaserSample sample;
  if (!on || !tip.allFinite() || !(dt > 0)) {
    fibre.firing = false;
    return sample;
  }
  if (!fibre.firing) {  // a new stroke starts here
    fibre.firing = true;
    fibre.last_tip = tip;
    return sample;
  }
  const Eigen::Vector3d from = fibre.last_tip;
  fibre.last_tip = tip;
  const double length = (tip - from).norm();
  sample.speed = length / dt;
  if (!(length > 0) || sample.speed > patch.vaporisation_speed) return sample;

  const double width = patch.spot_diameter;
  const Eigen::Vector3d lo = from.cwiseMin(tip).array() - (0.5 * width + patch.laser_reach);
  const Eigen::Vector3d hi = from.cwiseMax(tip).array() + (0.5 * width + patch.laser_reach);
  for (int t = 0; t < patch.triangle_count(); ++t) {
    if (state.separated[t] >= 1) continue;
    const Triangle& tri = patch.triangles[t];
    Eigen::Vector3d tri_lo = patch.positions.col(tri[0]), tri_hi = tri_lo;
    for (int k = 1; k < 3; ++k) {
      tri_lo = tri_lo.cwiseMin(patch.positions.col(tri[k]));
      tri_hi = tri_hi.cwiseMax(patch.positions.col(tri[k]));
    }
    if ((tri_hi.array() < lo.array()).any() || (tri_lo.array() > hi.array()).any()) continue;
    const Eigen::Vector3d n = patch.normals[t];
    const Eigen::Vector3d corner = patch.positions.col(tri[0]);
    if (std::abs((from - corner).dot(n)) > patch.laser_reach ||
        std::abs((tip - corner).dot(n)) > patch.laser_reach)
      continue;
    sample.vaporised +=
        separate_in_triangle(patch, state, t, strip_area_in_triangle(patch, t, from, tip, width));
  }
  sample.vaporising = sample.vaporised > 0;
  return sample;
}

}  // namespace cohaptic
