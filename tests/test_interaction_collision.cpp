// The node-polygon collision test (Eq. (0), the foot of the perpendicular, the target
// point) against brute force on 10^4 random configurations: random fans of triangles
// around a passive node (convex, concave and saddle-shaped) and random active nodes in
// front of and behind them. The brute force finds each triangle's closest point to the
// active node by the Voronoi-region method (closest_point_on_triangle): a foot lies
// inside its polygon exactly when that closest point is interior (all three weights
// positive), and the target is then the nearest of those points.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <random>

#include "common/contact/closest_point_on_triangle.h"
#include "common/interaction/node_polygon_collision.h"

namespace cohaptic {
namespace {

struct Fan {
  Eigen::Matrix3Xd positions;  // column 0: the passive node; 1..n: its ring
  SurfaceAdjacency surface;
};

// A closed fan of `ring` triangles around node 0, counter-clockwise seen from +z (outside).
Fan random_fan(std::mt19937& rng) {
  std::uniform_int_distribution<int> ring_size(3, 8);
  std::uniform_real_distribution<double> unit(0, 1), height(-0.6, 0.6), shift(-0.5, 0.5);
  const int ring = ring_size(rng);
  Fan fan;
  fan.positions.resize(3, ring + 1);
  fan.positions.col(0) = Eigen::Vector3d(shift(rng), shift(rng), shift(rng));
  std::vector<Triangle> triangles;
  for (int i = 0; i < ring; ++i) {
    // Angles spread round the circle with jitter, so the ring stays ordered.
    const double angle = 2 * M_PI * (i + 0.8 * unit(rng)) / ring;
    const double radius = 0.3 + unit(rng);
    fan.positions.col(i + 1) =
        fan.positions.col(0) +
        Eigen::Vector3d(radius * std::cos(angle), radius * std::sin(angle), height(rng));
    triangles.push_back({0, i + 1, (i + 1) % ring + 1});
  }
  fan.surface = make_surface_adjacency(triangles, ring + 1);
  return fan;
}

struct BruteForceCollisions {
  bool collides = false;
  int triangle = -1;
  TriangleClosestPoint target;
};

BruteForceCollisions brute_force(const Fan& fan, const Eigen::Vector3d& active) {
  BruteForceCollisions answer;
  bool behind_every_plane = true;
  double nearest = INFINITY;
  for (int t = 0; t < static_cast<int>(fan.surface.triangles.size()); ++t) {
    const Triangle& tri = fan.surface.triangles[static_cast<std::size_t>(t)];
    const Eigen::Vector3d a = fan.positions.col(tri[0]), b = fan.positions.col(tri[1]),
                          c = fan.positions.col(tri[2]);
    // Orientation of the tetrahedron (a, b, c, active): positive when active is in front.
    const double orientation =
        Eigen::Matrix3d((Eigen::Matrix3d() << b - a, c - a, active - a).finished()).determinant();
    if (orientation > 0) behind_every_plane = false;
    const TriangleClosestPoint closest = closest_point_on_triangle(active, a, b, c);
    const double distance = (closest.point - active).norm();
    if (closest.weights.minCoeff() > 0 && distance < nearest) {
      nearest = distance;
      answer.triangle = t;
      answer.target = closest;
    }
  }
  answer.collides = behind_every_plane && answer.triangle >= 0;
  return answer;
}

TEST(InteractionCollision, AgreesWithBruteForceClosestPointsOnRandomFans) {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> offset(-1.2, 1.2);
  int collisions = 0, behind_without_foot = 0, in_front = 0;
  for (int trial = 0; trial < 10000; ++trial) {
    const Fan fan = random_fan(rng);
    const Eigen::Vector3d active =
        fan.positions.col(0) + Eigen::Vector3d(offset(rng), offset(rng), offset(rng));
    const BruteForceCollisions expected = brute_force(fan, active);
    const bool instant = instant_collision_test(active, 0, fan.positions, fan.surface);
    const auto target = node_polygon_collision(active, 0, fan.positions, fan.surface);
    ASSERT_EQ(target.has_value(), expected.collides) << "trial " << trial;
    if (!instant) ++in_front;
    if (instant && !expected.collides) ++behind_without_foot;
    if (!target) continue;
    ++collisions;
    EXPECT_EQ(target->triangle, expected.triangle) << "trial " << trial;
    EXPECT_LT((target->point - expected.target.point).norm(), 1e-12) << "trial " << trial;
    EXPECT_LT((target->weights - expected.target.weights).norm(), 1e-9) << "trial " << trial;
    EXPECT_NEAR(target->weights.sum(), 1, 1e-12);
  }
  // Every branch is exercised many times.
  EXPECT_GT(collisions, 500);
  EXPECT_GT(behind_without_foot, 100);
  EXPECT_GT(in_front, 1000);
}

TEST(InteractionCollision, OnePolygonsTargetIsTheFootWithTheAreaRatiosAsWeights) {
  Eigen::Matrix3Xd positions(3, 4);
  positions << 0, 1, 0, -1,  //
      0, 0, 1, -1,           //
      0, 0, 0, 0;
  // Triangles around node 0, all facing +z.
  const SurfaceAdjacency surface = make_surface_adjacency({{0, 1, 2}, {0, 2, 3}, {0, 3, 1}}, 4);
  const Eigen::Vector3d active(0.2, 0.3, -0.05);
  const auto target = node_polygon_collision(active, 0, positions, surface);
  ASSERT_TRUE(target);
  EXPECT_EQ(target->triangle, 0);
  EXPECT_LT((target->point - Eigen::Vector3d(0.2, 0.3, 0)).norm(), 1e-15);
  // alpha = area(T, B, C) / area(A, B, C) and so on: the barycentric coordinates.
  EXPECT_LT((target->weights - Eigen::Vector3d(0.5, 0.2, 0.3)).norm(), 1e-15);
  // In front of the surface: Eq. (0) fails.
  EXPECT_FALSE(node_polygon_collision(Eigen::Vector3d(0.2, 0.3, 0.05), 0, positions, surface));
}

}  // namespace
}  // namespace cohaptic
