// Closest point on a triangle to a query point, with its barycentric (area) coordinates.
//
// The weights w sum to one, are non-negative, and are exactly zero for the vertices the
// closest point does not depend on, so the feature it lies on can be read from them:
// no zero -> the face interior, one zero -> an edge, two zeros -> a vertex.
// Degenerate triangles (zero area) are handled: the closest point on their edges is used.
#pragma once

#include <Eigen/Core>

namespace cohaptic {

struct TriangleClosestPoint {
  Eigen::Vector3d point;    ///< on the triangle
  Eigen::Vector3d weights;  ///< point = w0 a + w1 b + w2 c
};

TriangleClosestPoint closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                               const Eigen::Vector3d& b, const Eigen::Vector3d& c);

}  // namespace cohaptic
