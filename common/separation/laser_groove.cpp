#include "common/separation/laser_groove.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>

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

// Whether `p` lies on segment s's strip: within its length and its half width of its line.
bool on_segment_strip(const GrooveSegment& s, const Eigen::Vector3d& p) noexcept {
  const Eigen::Vector3d d = s.b - s.a;
  const double length_squared = d.squaredNorm();
  if (!(length_squared > 0)) return false;
  const double along = (p - s.a).dot(d) / length_squared;
  if (along < 0 || along > 1) return false;
  return (p - s.a - along * d).squaredNorm() <= 0.25 * s.width * s.width;
}

}  // namespace

double uncovered_share(const GrooveRecord& groove, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b, double width,
                       const Eigen::Vector3d& normal) noexcept {
  constexpr int kAlong = 4, kAcross = 16;  // 64 samples: one bit each of `covered`
  const Eigen::Vector3d d = b - a;
  Eigen::Vector3d across = normal.cross(d);
  if (groove.count == 0 || !(across.norm() > 0)) return 1;
  across.normalize();
  std::array<Eigen::Vector3d, kAlong * kAcross> samples;
  for (int i = 0; i < kAlong; ++i)
    for (int j = 0; j < kAcross; ++j)
      samples[static_cast<std::size_t>(i * kAcross + j)] =
          a + (i + 0.5) / kAlong * d + ((j + 0.5) / kAcross - 0.5) * width * across;
  // Only the segments whose box, widened by half their width, meets the strip's.
  const Eigen::Vector3d lo = a.cwiseMin(b).array() - 0.5 * width,
                        hi = a.cwiseMax(b).array() + 0.5 * width;
  constexpr std::uint64_t kAll = ~std::uint64_t{0};
  std::uint64_t covered = 0;
  for (std::size_t k = 0; k < groove.count && covered != kAll; ++k) {
    const GrooveSegment& s = groove.segments[k];
    const Eigen::Vector3d s_lo = s.a.cwiseMin(s.b).array() - 0.5 * s.width,
                          s_hi = s.a.cwiseMax(s.b).array() + 0.5 * s.width;
    if ((s_hi.array() < lo.array()).any() || (s_lo.array() > hi.array()).any()) continue;
    for (std::size_t p = 0; p < samples.size(); ++p)
      if (!(covered >> p & 1u) && on_segment_strip(s, samples[p])) covered |= std::uint64_t{1} << p;
  }
  return 1.0 - static_cast<double>(std::popcount(covered)) / (kAlong * kAcross);
}

void remember_groove(GrooveRecord& groove, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                     double width) noexcept {
  constexpr double kMergeTolerance = 0.02;  // of the width
  if (groove.count > 0) {
    GrooveSegment& last = groove.segments[groove.count - 1];
    if (last.b == a && last.width == width) {
      // The strip continues the last segment: merge if the line a0-b still passes within
      // the tolerance of every tick merged so far (the old end's distance from the new
      // line, added to what earlier merges strayed, bounds it).
      const Eigen::Vector3d line = b - last.a;
      const double length = line.norm();
      if (length > 0 && (a - last.a).dot(line) < length * length) {
        const Eigen::Vector3d u = line / length;
        const Eigen::Vector3d off = (a - last.a) - (a - last.a).dot(u) * u;
        const double slack = last.slack + off.norm();
        if (slack <= kMergeTolerance * width) {
          last.b = b;
          last.slack = slack;
          return;
        }
      }
    }
  }
  if (groove.count >= groove.segments.size()) {
    groove.full = true;
    return;
  }
  groove.segments[groove.count++] = GrooveSegment{a, b, width, 0.0};
}

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
    const double fresh = uncovered_share(state.groove, from, tip, width, n);
    if (fresh <= 0) continue;
    sample.vaporised += separate_in_triangle(
        patch, state, t, fresh * strip_area_in_triangle(patch, t, from, tip, width));
  }
  if (sample.vaporised > 0) remember_groove(state.groove, from, tip, width);
  sample.vaporising = sample.vaporised > 0;
  return sample;
}

}  // namespace cohaptic
