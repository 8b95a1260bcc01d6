#include "common/contact/aabb_tree.h"

#include <algorithm>
#include <array>
#include <fmt/format.h>
#include <numeric>

#include "common/util/error.h"

namespace cohaptic {
namespace {

/// Squared distance from p to the box [lo, hi] (zero inside).
double box_distance2(const Eigen::Vector3d& p, const Eigen::Vector3d& lo,
                     const Eigen::Vector3d& hi) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double below = lo[k] - p[k], above = p[k] - hi[k];
    const double d = std::max({below, above, 0.0});
    d2 += d * d;
  }
  return d2;
}

/// Slack on segment parameters when a box is tested: a triangle's crossing, computed
/// another way, may differ from its box's entry by rounding, and pruning must never lose it.
constexpr double kSegmentSlack = 1e-12;

/// Where the segment from + t d, 0 <= t <= t_max, enters the box [lo, hi] (with the
/// slack above); false if it misses the box.
bool segment_box_interval(const Eigen::Vector3d& from, const Eigen::Vector3d& d, double t_max,
                          const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double& enter) {
  double t0 = 0, t1 = t_max + kSegmentSlack;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0) {
      if (from[k] < lo[k] || from[k] > hi[k]) return false;
      continue;
    }
    double a = (lo[k] - from[k]) / d[k], b = (hi[k] - from[k]) / d[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1 + kSegmentSlack) return false;
  }
  enter = t0;
  return true;
}

}  // namespace

AabbTree::AabbTree(const TriangleSurface& surface)
    : AabbTree(surface.vertices, surface.triangles) {}

AabbTree::AabbTree(const Eigen::Matrix3Xd& vertices, std::span<const Triangle> triangles) {
  const int n = static_cast<int>(triangles.size());
  if (n == 0) return;
  corners_.resize(triangles.size());
  std::vector<Eigen::Vector3d> centroids(triangles.size());
  for (int t = 0; t < n; ++t) {
    for (int k = 0; k < 3; ++k) {
      const int v = triangles[t][k];
      if (v < 0 || v >= vertices.cols())
        throw Error(
            fmt::format("AABB tree: triangle {} refers to vertex {}, but there are {} vertices", t,
                        v, vertices.cols()));
      if (!vertices.col(v).allFinite())
        throw Error(fmt::format("AABB tree: vertex {} (used by triangle {}) is not finite", v, t));
    }
    // Kept in input order for now; permuted into leaf order once the tree is built.
    corners_[t] = {vertices.col(triangles[t][0]), vertices.col(triangles[t][1]),
                   vertices.col(triangles[t][2])};
    centroids[t] = (corners_[t].a + corners_[t].b + corners_[t].c) / 3;
  }
  std::vector<int> order(triangles.size());
  std::iota(order.begin(), order.end(), 0);
  // A median split halves the count at every level: about 2n / kLeafSize nodes.
  nodes_.reserve(static_cast<std::size_t>(2 * (n / kLeafSize) + 2));
  build(order, centroids, 0, n, 1);
  if (depth_ > kMaxDepth)  // cannot happen below 2^60 triangles; guards the query stack
    throw Error(fmt::format("AABB tree: depth {} exceeds {}", depth_, kMaxDepth));

  std::vector<Corners> leaf_corners(corners_.size());
  for (int slot = 0; slot < n; ++slot) leaf_corners[slot] = corners_[order[slot]];
  corners_ = std::move(leaf_corners);
  triangle_index_ = std::move(order);
}

int AabbTree::build(std::vector<int>& order, const std::vector<Eigen::Vector3d>& centroids,
                    int begin, int end, int level) {
  depth_ = std::max(depth_, level);
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  Eigen::Vector3d centroid_lo = lo, centroid_hi = hi;
  for (int i = begin; i < end; ++i) {
    const Corners& c = corners_[order[i]];
    lo = lo.cwiseMin(c.a).cwiseMin(c.b).cwiseMin(c.c);
    hi = hi.cwiseMax(c.a).cwiseMax(c.b).cwiseMax(c.c);
    centroid_lo = centroid_lo.cwiseMin(centroids[order[i]]);
    centroid_hi = centroid_hi.cwiseMax(centroids[order[i]]);
  }
  nodes_[index].lo = lo;
  nodes_[index].hi = hi;
  if (end - begin <= kLeafSize) {
    nodes_[index].first_or_right = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  int axis = 0;
  (centroid_hi - centroid_lo).maxCoeff(&axis);
  const int middle = begin + (end - begin) / 2;
  std::nth_element(order.begin() + begin, order.begin() + middle, order.begin() + end,
                   [&](int x, int y) { return centroids[x][axis] < centroids[y][axis]; });
  build(order, centroids, begin, middle, level + 1);  // left child: index + 1
  const int right = build(order, centroids, middle, end, level + 1);
  nodes_[index].first_or_right = right;
  nodes_[index].count = 0;
  return index;
}

AabbHit AabbTree::closest_triangle(const Eigen::Vector3d& p, double max_distance) const {
  AabbHit hit;
  if (nodes_.empty() || !(max_distance >= 0)) return hit;
  double best2 = max_distance * max_distance;

  struct Pending {
    int node;
    double distance2;
  };
  std::array<Pending, kMaxDepth> stack;
  int top = 0;
  int node = 0;
  if (box_distance2(p, nodes_[0].lo, nodes_[0].hi) > best2) return hit;
  for (;;) {
    // Descend towards the nearer child, leaving the farther one for later.
    for (;;) {
      const Node& current = nodes_[node];
      if (current.count > 0) {
        for (int slot = current.first_or_right; slot < current.first_or_right + current.count;
             ++slot) {
          const Corners& c = corners_[slot];
          const TriangleClosestPoint q = closest_point_on_triangle(p, c.a, c.b, c.c);
          const double d2 = (p - q.point).squaredNorm();
          const int t = triangle_index_[slot];
          if (d2 < best2 || (d2 == best2 && (hit.triangle < 0 || t < hit.triangle))) {
            best2 = d2;
            hit.triangle = t;
            hit.closest = q;
          }
        }
        break;
      }
      int near = node + 1, far = current.first_or_right;
      double near2 = box_distance2(p, nodes_[near].lo, nodes_[near].hi);
      double far2 = box_distance2(p, nodes_[far].lo, nodes_[far].hi);
      if (far2 < near2) {
        std::swap(near, far);
        std::swap(near2, far2);
      }
      if (near2 > best2) break;
      if (far2 <= best2) stack[top++] = {far, far2};
      node = near;
    }
    // Resume at the nearest-pushed box that can still hold something closer.
    while (top > 0 && stack[top - 1].distance2 > best2) --top;
    if (top == 0) break;
    node = stack[--top].node;
  }
  if (hit.triangle >= 0) hit.distance2 = best2;
  return hit;
}

AabbCrossing AabbTree::first_crossing(const Eigen::Vector3d& from,
                                      const Eigen::Vector3d& to) const noexcept {
  AabbCrossing hit;
  const Eigen::Vector3d d = to - from;
  if (nodes_.empty() || !from.allFinite() || !d.allFinite()) return hit;
  // Boxes are tested against the segment up to the best crossing so far (inclusive: a box
  // touched exactly there may still hold a tie with a lower index).
  double best_t = 1;
  struct Pending {
    int node;
    double enter;
  };
  std::array<Pending, kMaxDepth> stack;
  int top = 0;
  int node = 0;
  double enter = 0;
  if (!segment_box_interval(from, d, best_t, nodes_[0].lo, nodes_[0].hi, enter)) return hit;
  for (;;) {
    for (;;) {
      const Node& current = nodes_[node];
      if (current.count > 0) {
        for (int slot = current.first_or_right; slot < current.first_or_right + current.count;
             ++slot) {
          const Corners& c = corners_[slot];
          const auto crossing = segment_triangle_crossing(from, to, c.a, c.b, c.c);
          if (!crossing) continue;
          const int t = triangle_index_[slot];
          if (crossing->t < best_t ||
              (crossing->t == best_t && (hit.triangle < 0 || t < hit.triangle))) {
            best_t = crossing->t;
            hit.triangle = t;
            hit.crossing = *crossing;
          }
        }
        break;
      }
      int near = node + 1, far = current.first_or_right;
      double near_enter = 0, far_enter = 0;
      const bool near_hit =
          segment_box_interval(from, d, best_t, nodes_[near].lo, nodes_[near].hi, near_enter);
      const bool far_hit =
          segment_box_interval(from, d, best_t, nodes_[far].lo, nodes_[far].hi, far_enter);
      if (!near_hit && !far_hit) break;
      if (!near_hit || (far_hit && far_enter < near_enter)) {
        std::swap(near, far);
        std::swap(near_enter, far_enter);
      }
      if (near_hit && far_hit) stack[top++] = {far, far_enter};
      node = near;
    }
    // Resume at the most recently pushed box the segment still reaches before best_t.
    while (top > 0 && stack[top - 1].enter > best_t + kSegmentSlack) --top;
    if (top == 0) break;
    node = stack[--top].node;
  }
  return hit;
}

void AabbTree::triangles_near(const Eigen::Vector3d& p, double max_distance,
                              std::vector<int>& out) const {
  if (nodes_.empty() || !(max_distance >= 0)) return;
  const double reach2 = max_distance * max_distance;
  std::array<int, kMaxDepth + 1> stack;  // one pending sibling per level, and the root
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (box_distance2(p, node.lo, node.hi) > reach2) continue;
    if (node.count > 0) {
      for (int slot = node.first_or_right; slot < node.first_or_right + node.count; ++slot) {
        const Corners& c = corners_[slot];
        const Eigen::Vector3d lo = c.a.cwiseMin(c.b).cwiseMin(c.c),
                              hi = c.a.cwiseMax(c.b).cwiseMax(c.c);
        if (box_distance2(p, lo, hi) <= reach2) out.push_back(triangle_index_[slot]);
      }
    } else {
      // Depth-first: at most one pending sibling per level.
      stack[top++] = node.first_or_right;
      stack[top++] = static_cast<int>(&node - nodes_.data()) + 1;
    }
  }
}

}  // namespace cohaptic
