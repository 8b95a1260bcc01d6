// ObstacleClearance: which moving points certainly lie on the allowed side of every
// obstacle, so that only the others are queried against the obstacles' AABB trees.
//
// The distance to a surface is 1-Lipschitz in the point: a point found at `anchor` with
// signed distance r > 0 to the nearest obstacle stays on the allowed side of every obstacle
// anywhere within r of that anchor. Each point keeps the anchor and radius of its last
// query (at first its rest position and rest clearance); a point that has moved less than
// its radius, less a margin of kMargin that dwarfs the queries' rounding, needs no query.
// A screened point is therefore exactly one a query would have found clear: the decisions,
// and every bit that follows from them, are those of querying every point. Allocates
// nothing after construction. Each point also keeps the distance gradient (the nearest
// obstacle's normal) at its anchor, for a first-order estimate of its distance now: where
// the points are heading, not only where they are certainly clear. Units: m.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/contact/obstacle_distance.h"

namespace cohaptic {

class ObstacleClearance {
 public:
  /// A skipped point is at least this far from every obstacle, whatever the rounding [m].
  static constexpr double kMargin = 1e-9;

  ObstacleClearance() = default;
  /// One point per column of `rest_points`, anchored there with its clearance to `obstacles`.
  ObstacleClearance(std::span<const ObstacleDistance> obstacles,
                    const Eigen::Matrix3Xd& rest_points);

  /// A lower bound of point i's distance to the nearest obstacle at `position` [m].
  double lower_bound(std::size_t i, const Eigen::Vector3d& position) const {
    return radii_[i] - (position - anchors_.col(static_cast<Eigen::Index>(i))).norm();
  }
  /// Point i at `position` is certainly on the allowed side of every obstacle.
  bool certainly_clear(std::size_t i, const Eigen::Vector3d& position) const {
    return lower_bound(i, position) > kMargin;
  }
  /// First-order estimate of point i's distance to the nearest obstacle at `position` [m]:
  /// exact for a plane, close for a smooth surface near the anchor.
  double estimate(std::size_t i, const Eigen::Vector3d& position) const {
    const auto k = static_cast<Eigen::Index>(i);
    return radii_[i] + normals_.col(k).dot(position - anchors_.col(k));
  }
  /// A query found point i at `position` at `clearance` from the nearest obstacle (<= 0 when
  /// it penetrates one), whose normal there is `normal`: it becomes the point's anchor.
  void record(std::size_t i, const Eigen::Vector3d& position, double clearance,
              const Eigen::Vector3d& normal) {
    const auto k = static_cast<Eigen::Index>(i);
    anchors_.col(k) = position;
    normals_.col(k) = normal;
    radii_[i] = clearance;
  }
  /// The clearance recorded for point i (at rest until it is queried again) [m].
  double radius(std::size_t i) const { return radii_[i]; }

 private:
  Eigen::Matrix3Xd anchors_, normals_;
  std::vector<double> radii_;
};

}  // namespace cohaptic
