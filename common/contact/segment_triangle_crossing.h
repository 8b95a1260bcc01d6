// Where a line segment crosses a triangle: the segment parameter t of the crossing
// (point = from + t (to - from), 0 <= t <= 1) and the crossing's area coordinates.
//
// Both sides of the triangle count (a shaft may come from either side of an open tissue
// sheet). Edges and corners are inclusive. A segment lying in the triangle's plane, and a
// degenerate triangle, cross nothing: such a segment grazes the surface without passing
// through it, and a neighbouring triangle at an angle reports the crossing instead.
// Units: those of the points (m inside cohaptic).
#pragma once

#include <Eigen/Core>
#include <optional>

namespace cohaptic {

struct SegmentTriangleCrossing {
  double t = 0;             ///< along the segment, in [0, 1]
  Eigen::Vector3d weights;  ///< point = w0 a + w1 b + w2 c, non-negative, summing to one
};

std::optional<SegmentTriangleCrossing> segment_triangle_crossing(const Eigen::Vector3d& from,
                                                                 const Eigen::Vector3d& to,
                                                                 const Eigen::Vector3d& a,
                                                                 const Eigen::Vector3d& b,
                                                                 const Eigen::Vector3d& c) noexcept;

}  // namespace cohaptic
