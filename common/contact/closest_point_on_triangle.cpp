#include "common/contact/closest_point_on_triangle.h"

#include <Eigen/Geometry>
#include <algorithm>

namespace cohaptic {

// Voronoi-region walk after Ericson, "Real-Time Collision Detection", 5.1.5.
namespace {

// Zero-area triangle: its closest point lies on one of its edges; take the best of the three.
TriangleClosestPoint closest_point_on_edges(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                            const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  TriangleClosestPoint best{a, {1, 0, 0}};
  double best_distance = (p - a).squaredNorm();
  const Eigen::Vector3d corners[3] = {a, b, c};
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d& s = corners[i];
    const Eigen::Vector3d& e = corners[(i + 1) % 3];
    const double length2 = (e - s).squaredNorm();
    const double t = length2 > 0 ? std::clamp((p - s).dot(e - s) / length2, 0.0, 1.0) : 0.0;
    const Eigen::Vector3d q = s + t * (e - s);
    if ((p - q).squaredNorm() < best_distance) {
      best_distance = (p - q).squaredNorm();
      best.point = q;
      best.weights.setZero();
      best.weights[i] = 1 - t;
      best.weights[(i + 1) % 3] = t;
    }
  }
  return best;
}

}  // namespace

TriangleClosestPoint closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                               const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  // Degenerate (sine of the angle at a below 1e-12): the face formula below would divide
  // rounding noise by rounding noise, so use the edges instead.
  if (ab.cross(ac).squaredNorm() <= 1e-24 * ab.squaredNorm() * ac.squaredNorm())
    return closest_point_on_edges(p, a, b, c);
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {a, {1, 0, 0}};

  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {b, {0, 1, 0}};

  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0 && d1 - d3 > 0) {
    const double v = d1 / (d1 - d3);
    return {a + v * ab, {1 - v, v, 0}};
  }

  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {c, {0, 0, 1}};

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0 && d2 - d6 > 0) {
    const double w = d2 / (d2 - d6);
    return {a + w * ac, {1 - w, 0, w}};
  }

  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0 && (d4 - d3) + (d5 - d6) > 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b + w * (c - b), {0, 1 - w, w}};
  }

  const double sum = va + vb + vc;
  if (!(sum > 0)) return closest_point_on_edges(p, a, b, c);
  const double v = vb / sum, w = vc / sum;
  return {a + v * ab + w * ac, {1 - v - w, v, w}};
}

}  // namespace cohaptic
