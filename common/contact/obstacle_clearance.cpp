#include "common/contact/obstacle_clearance.h"

#include <algorithm>
#include <limits>

namespace cohaptic {

ObstacleClearance::ObstacleClearance(std::span<const ObstacleDistance> obstacles, const Eigen::Matrix3Xd& rest_points)
    : anchors_(rest_points), radii_(static_cast<std::size_t>(rest_points.cols()), std::numeric_limits<double>::infinity()) {
  for (Eigen::Index i = 0; i < rest_points.cols(); ++i)
    for (const ObstacleDistance& obstacle : obstacles)
      radii_[static_cast<std::size_t>(i)] =
          std::min(radii_[static_cast<std::size_t>(i)], obstacle.signed_distance(rest_points.col(i)));
}

}  // namespace cohaptic
