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
// nothing after construction. Units: m.
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
  ObstacleClearance(std::span<const ObstacleDistance> obstacles, const Eigen::Matrix3Xd& rest_points);

  /// Point i at `position` is certainly on the allowed side of every obstacle.
  bool certainly_clear(std::size_t i, const Eigen::Vector3d& position) const {
    return (position - anchors_.col(static_cast<Eigen::Index>(i))).norm() < radii_[i] - kMargin;
  }
  /// A query found point i at `position` at `clearance` from the nearest obstacle (<= 0 when
  /// it penetrates one): it becomes the point's anchor.
  void record(std::size_t i, const Eigen::Vector3d& position, double clearance) {
    anchors_.col(static_cast<Eigen::Index>(i)) = position;
    radii_[i] = clearance;
  }
  /// The clearance recorded for point i (at rest until it is queried again) [m].
  double radius(std::size_t i) const { return radii_[i]; }

 private:
  Eigen::Matrix3Xd anchors_;
  std::vector<double> radii_;
};

}  // namespace cohaptic
