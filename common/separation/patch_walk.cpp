#include "common/separation/patch_walk.h"

#include <algorithm>
#include <limits>

namespace cohaptic {
namespace {

constexpr int kMaxCrossings = 256;

Eigen::Vector3d point_at(const SeparationPatch& patch, int t, const Eigen::Vector3d& w) noexcept {
  const Triangle& tri = patch.triangles[t];
  return w[0] * patch.positions.col(tri[0]) + w[1] * patch.positions.col(tri[1]) +
         w[2] * patch.positions.col(tri[2]);
}

}  // namespace

PatchWalk walk_on_patch(const SeparationPatch& patch, const SeparationState& state, int triangle,
                        const Eigen::Vector3d& weights, const Eigen::Vector3d& direction,
                        double distance, bool stop_at_crack_edges) noexcept {
  PatchWalk walk;
  walk.triangle = triangle;
  walk.weights = weights;
  double remaining = std::max(distance, 0.0);
  for (int crossing = 0; crossing < kMaxCrossings && remaining > 0; ++crossing) {
    const Triangle& tri = patch.triangles[walk.triangle];
    const Eigen::Vector3d n = patch.normals[walk.triangle];
    Eigen::Vector3d d = direction - direction.dot(n) * n;
    if (!(d.norm() > 0)) break;
    d.normalize();
    // d = u e1 + v e2 in the triangle's plane, so the area coordinates change at (-u-v, u, v).
    const Eigen::Vector3d a = patch.positions.col(tri[0]);
    const Eigen::Vector3d e1 = patch.positions.col(tri[1]) - a,
                          e2 = patch.positions.col(tri[2]) - a;
    const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2);
    const double det = g11 * g22 - g12 * g12;
    if (!(det > 0)) break;
    const double u = (g22 * d.dot(e1) - g12 * d.dot(e2)) / det;
    const double v = (g11 * d.dot(e2) - g12 * d.dot(e1)) / det;
    const Eigen::Vector3d rate(-u - v, u, v);
    double exit = std::numeric_limits<double>::infinity();
    int vertex = -1;
    for (int k = 0; k < 3; ++k)
      if (rate[k] < 0 && -walk.weights[k] / rate[k] < exit) {
        exit = std::max(-walk.weights[k] / rate[k], 0.0);
        vertex = k;
      }
    if (remaining <= exit) {
      walk.weights += remaining * rate;
      walk.travelled += remaining;
      break;
    }
    // Out through the edge opposite `vertex`, i.e. edge (vertex + 1, vertex + 2).
    walk.weights += exit * rate;
    walk.weights[vertex] = 0;
    walk.travelled += exit;
    remaining -= exit;
    const int edge = (vertex + 1) % 3;
    const int next = patch.neighbours[walk.triangle][edge];
    if (next < 0) {
      walk.stop = PatchWalk::Stop::rim;
      break;
    }
    if (stop_at_crack_edges && is_open(state, walk.triangle) != is_open(state, next)) {
      walk.stop = PatchWalk::Stop::crack_edge;
      break;
    }
    Eigen::Vector3d moved = Eigen::Vector3d::Zero();
    const Triangle& other = patch.triangles[next];
    for (int k = 0; k < 3; ++k)
      for (int m = 0; m < 3; ++m)
        if (other[k] == tri[m]) moved[k] = walk.weights[m];
    walk.weights = moved;
    walk.triangle = next;
  }
  walk.weights = walk.weights.cwiseMax(0.0);
  walk.weights /= walk.weights.sum();
  walk.point = point_at(patch, walk.triangle, walk.weights);
  return walk;
}

}  // namespace cohaptic
