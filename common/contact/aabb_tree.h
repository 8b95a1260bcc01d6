// AabbTree: a static bounding-volume hierarchy (axis-aligned boxes) over a list of
// triangles, for closest-triangle queries against large rigid surfaces (obstacles such as
// the inner skull) at haptic rates.
//
// Built once in O(n log n): median split of the triangle centroids along the longest axis
// of their bounds, leaves of at most 4 triangles, nodes in one flat depth-first array (a
// node's first child follows it). The tree keeps its own copy of every triangle's corners,
// so it does not refer to the vertices it was built from. A query visits the nearer child
// first and skips every box farther than the best triangle found so far; it allocates
// nothing (a fixed stack of kMaxDepth entries; the median split keeps the depth at about
// log2(n / 4) + 1). Ties between triangles at exactly the same distance go to the lowest
// index, as a linear scan would. The same tree answers which triangle a segment crosses
// first (an instrument's shaft against a tissue surface), visiting only the boxes the
// segment passes through before the best crossing found so far. Units: those of the
// vertices (m inside cohaptic).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <span>
#include <vector>

#include "common/contact/closest_point_on_triangle.h"
#include "common/contact/segment_triangle_crossing.h"
#include "common/mesh/tet_mesh.h"
#include "common/mesh/triangle_surface.h"

namespace cohaptic {

struct AabbHit {
  int triangle = -1;                                           ///< -1: none within reach
  TriangleClosestPoint closest{};                              ///< point and area coordinates
  double distance2 = std::numeric_limits<double>::infinity();  ///< squared distance to p
};

struct AabbCrossing {
  int triangle = -1;                   ///< -1: the segment crosses nothing
  SegmentTriangleCrossing crossing{};  ///< where along the segment, and where on the triangle
};

class AabbTree {
 public:
  static constexpr int kLeafSize = 4;
  static constexpr int kMaxDepth = 64;

  /// An empty tree: every query finds nothing.
  AabbTree() = default;
  /// Tree over `triangles`, whose indices refer to columns of `vertices`. Throws Error if
  /// an index is out of range or a used vertex is not finite.
  AabbTree(const Eigen::Matrix3Xd& vertices, std::span<const Triangle> triangles);
  explicit AabbTree(const TriangleSurface& surface);

  /// The triangle closest to `p` among those within `max_distance` (inclusive), with the
  /// closest point on it; triangle -1 if there is none (or the tree is empty).
  AabbHit closest_triangle(const Eigen::Vector3d& p,
                           double max_distance = std::numeric_limits<double>::infinity()) const;

  /// The triangle the segment from -> to crosses first (smallest segment parameter; ties
  /// to the lowest index, as a linear scan would), as segment_triangle_crossing decides
  /// for each triangle; triangle -1 if it crosses none.
  AabbCrossing first_crossing(const Eigen::Vector3d& from,
                              const Eigen::Vector3d& to) const noexcept;

  /// Appends to `out` the input index of every triangle whose bounding box is within
  /// `max_distance` of `p` (inclusive): a superset of the triangles within that distance, in
  /// no particular order. Allocates only when `out` grows.
  void triangles_near(const Eigen::Vector3d& p, double max_distance, std::vector<int>& out) const;

  int triangle_count() const { return static_cast<int>(triangle_index_.size()); }
  int node_count() const { return static_cast<int>(nodes_.size()); }
  /// Levels of nodes (1 for a single leaf, 0 for an empty tree).
  int depth() const { return depth_; }

 private:
  struct Node {
    Eigen::Vector3d lo, hi;  ///< bounds of every triangle below
    int first_or_right = 0;  ///< leaf: first slot in triangle_index_; inner: right child
    int count = 0;           ///< leaf: triangles in it (1..kLeafSize); inner: 0
  };
  struct Corners {
    Eigen::Vector3d a, b, c;
  };

  int build(std::vector<int>& order, const std::vector<Eigen::Vector3d>& centroids, int begin,
            int end, int level);

  std::vector<Node> nodes_;
  std::vector<Corners> corners_;     ///< per slot, in leaf order
  std::vector<int> triangle_index_;  ///< per slot: index in the input list
  int depth_ = 0;
};

}  // namespace cohaptic
