// ObstacleClearance (common/contact/obstacle_clearance.h) against querying every point:
// points random-walking inside an icosphere obstacle and beside a plane one, drifting out
// so that many penetrate. Every point the screen lets pass unqueried must be clear of every
// obstacle by at least the margin (checked by querying it all the same), and the screen
// must spare most queries (else it is not doing its job).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "common/contact/obstacle_clearance.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;

double nearest_obstacle(const std::vector<ObstacleDistance>& obstacles, const Vector3d& p) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const ObstacleDistance& obstacle : obstacles)
    nearest = std::min(nearest, obstacle.signed_distance(p));
  return nearest;
}

TEST(ObstacleClearance, PointsItSkipsAreClearOfEveryObstacleAndItSkipsMost) {
  std::mt19937 rng(7);
  const int count = 300;
  Eigen::Matrix3Xd rest(3, count);
  for (int i = 0; i < count; ++i)
    rest.col(i) =
        std::uniform_real_distribution<double>(0.2, 0.9)(rng) * testing::random_direction(rng);
  std::vector<ObstacleDistance> obstacles;
  obstacles.emplace_back(Obstacle{"ball", testing::make_icosphere(3, 1.0), std::nullopt}, rest);
  obstacles.emplace_back(Obstacle{"floor", {}, std::pair{Vector3d(0, 0, -0.8), Vector3d(0, 0, 1)}},
                         rest);
  ObstacleClearance clearance(obstacles, rest);
  for (int i = 0; i < count; ++i)
    EXPECT_EQ(clearance.radius(static_cast<std::size_t>(i)),
              nearest_obstacle(obstacles, rest.col(i)));

  // Each point walks in steps of up to 5 mm with a slight outward drift.
  Eigen::Matrix3Xd position = rest;
  long skipped = 0, queried = 0, penetrating = 0;
  for (int step = 0; step < 400; ++step) {
    for (int i = 0; i < count; ++i) {
      const auto slot = static_cast<std::size_t>(i);
      const Vector3d p = position.col(i);
      Vector3d next = p +
                      0.005 * std::uniform_real_distribution<double>(0, 1)(rng) *
                          testing::random_direction(rng) +
                      0.001 * p.normalized();
      if (next.norm() > 1.1) next = rest.col(i);  // far out: start again from rest
      position.col(i) = next;
      const double truth = nearest_obstacle(obstacles, next);
      if (clearance.certainly_clear(slot, next)) {
        ++skipped;
        ASSERT_GE(truth, ObstacleClearance::kMargin) << "point " << i << " at step " << step;
      } else {
        ++queried;
        penetrating += truth < 0;
        clearance.record(slot, next, truth, Vector3d::UnitZ());
      }
    }
  }
  std::printf("  %ld point checks: %ld skipped, %ld queried (%ld penetrating)\n", skipped + queried,
              skipped, queried, penetrating);
  EXPECT_GT(penetrating, 1000);     // the walk does reach the obstacles
  EXPECT_GT(skipped, 3 * queried);  // and the screen spares most queries
}

TEST(ObstacleClearance, APenetratingOrTouchingPointIsAlwaysQueried) {
  const Eigen::Matrix3Xd rest = Eigen::Vector3d(0, 0, 1).replicate(1, 1);
  std::vector<ObstacleDistance> obstacles;
  obstacles.emplace_back(Obstacle{"floor", {}, std::pair{Vector3d::Zero(), Vector3d(0, 0, 1)}},
                         rest);
  ObstacleClearance clearance(obstacles, rest);
  EXPECT_TRUE(clearance.certainly_clear(0, Vector3d(0, 0, 0.5)));
  EXPECT_FALSE(clearance.certainly_clear(0, Vector3d(0, 0, 0)));  // moved by the whole radius
  clearance.record(0, Vector3d(0, 0, -0.1), -0.1, Vector3d::UnitZ());
  EXPECT_FALSE(clearance.certainly_clear(0, Vector3d(0, 0, -0.1)));
  clearance.record(0, Vector3d(0, 0, 0), 0.0, Vector3d::UnitZ());
  EXPECT_FALSE(clearance.certainly_clear(0, Vector3d(0, 0, 0)));
}

TEST(ObstacleClearance, EstimatesThePlanesDistanceExactlyAndTheSpheresToSecondOrder) {
  const Eigen::Matrix3Xd rest =
      (Eigen::Matrix3Xd(3, 2) << 0, 0, 0, 0, 0.5, 0.6).finished();  // (0, 0, 0.5), (0, 0, 0.6)
  std::vector<ObstacleDistance> plane;
  plane.emplace_back(Obstacle{"floor", {}, std::pair{Vector3d(0, 0, 0.2), Vector3d(0, 0, 1)}},
                     rest);
  const ObstacleClearance flat(plane, rest);
  for (const Vector3d& p : {Vector3d(0.3, -0.1, 0.25), Vector3d(-1, 2, 0.9), Vector3d(0, 0, 0.1)})
    EXPECT_NEAR(flat.estimate(0, p), p.z() - 0.2, 1e-15);

  // Inside a unit ball (finely faceted): d = 1 - |p|, so moving sideways by s from the
  // anchor overestimates d by about s^2 / (2 |p|), under s^2 here.
  std::vector<ObstacleDistance> ball;
  ball.emplace_back(Obstacle{"ball", testing::make_icosphere(5, 1.0), std::nullopt}, rest);
  const ObstacleClearance round(ball, rest);
  for (double s : {0.01, 0.05, 0.1}) {
    const Vector3d p(s, 0, 0.6 - s);  // sideways and towards the wall
    const double truth = ball[0].signed_distance(p);
    EXPECT_NEAR(round.estimate(1, p), truth, s * s + 3e-3) << "step " << s;  // 3e-3: the faceting
  }
}

}  // namespace
}  // namespace cohaptic
