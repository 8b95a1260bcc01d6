// NearestTriangleCandidates: the few surface triangles that can be the nearest to a point,
// found through AABB trees, so that the nearest-triangle rules (closest_surface_point in
// surface_distance.h, nearest_triangle and find_contact in find_contact.h) scan a handful
// of triangles per query instead of the whole surface, and give the same answer.
//
// The candidates are every triangle whose bounding box lies within (1 + kSlack) times the
// nearest triangle's distance, plus kReach; they come out in ascending index, the order the
// full scans visit. A triangle farther than that cannot win, nor change which one wins:
// the rules' tie tolerances are 1e-12 relative (and 1e-12 m) at most, so a scan over the
// candidates visits every triangle that could tie, in the same order. One tree covers the
// whole surface, another the touchable triangles when they are not all of them. Queries
// allocate only while the output vectors grow. Units: m.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/contact/aabb_tree.h"
#include "common/mesh/boundary_surface.h"

namespace cohaptic {

class NearestTriangleCandidates {
 public:
  static constexpr double kSlack = 1e-6;  ///< relative to the nearest distance
  static constexpr double kReach = 1e-9;  ///< absolute [m]

  NearestTriangleCandidates() = default;
  /// `touchable_triangles`: surface triangle indices, ascending.
  NearestTriangleCandidates(const TetMesh& mesh, const BoundarySurface& surface,
                            std::span<const int> touchable_triangles);

  /// Replaces `surface` by the candidates among every surface triangle and `touchable` by
  /// those among the touchable triangles (surface triangle indices, ascending).
  void find(const Eigen::Vector3d& p, std::vector<int>& surface, std::vector<int>& touchable) const;

 private:
  static void near(const AabbTree& tree, std::span<const int> index, const Eigen::Vector3d& p,
                   std::vector<int>& out);

  AabbTree all_, touchable_;
  std::vector<int>
      touchable_index_;  ///< touchable tree's triangle k is surface triangle touchable_index_[k]
  bool every_triangle_touchable_ = false;
};

}  // namespace cohaptic
