#include "common/contact/obstacle_clearance.h"

#include <algorithm>
#include <limits>

namespace cohaptic {

ObstacleClearance::ObstacleClearance(std::span<const ObstacleDistance> obstacles,
                                     const Eigen::Matrix3Xd& rest_points)
    : anchors_(rest_points),
      normals_(Eigen::Matrix3Xd::Zero(3, rest_points.cols())),
      radii_(static_cast<std::size_t>(rest_points.cols()),
             std::numeric_limits<double>::infinity()) {
  for (Eigen::Index i = 0; i < rest_points.cols(); ++i)
    for (const ObstacleDistance& obstacle : obstacles) {
      const ObstaclePoint nearest = obstacle.closest_point(rest_points.col(i));
      if (nearest.signed_distance >= radii_[static_cast<std::size_t>(i)]) continue;
      radii_[static_cast<std::size_t>(i)] = nearest.signed_distance;
      normals_.col(i) = nearest.normal;
    }
}

}  // namespace cohaptic
