// ObstacleDistance (common/contact/obstacle_distance.h): a plane against its analytic
// signed distance; an icosphere against the unit sphere's 1 - |p|, within the faceting
// error computed from the triangles' planes, with the allowed side chosen by reference
// points inside or outside, either triangle orientation, and the error for a split object;
// an open square against hand-computed distances; the Colin27 inner skull with the brain
// surface as the object (skipped if shared/data is absent), with a printed timing of the
// AABB tree against a linear scan.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "common/contact/aabb_tree.h"
#include "common/contact/closest_point_on_triangle.h"
#include "common/contact/obstacle_distance.h"
#include "common/mesh/read_freesurfer.h"
#include "common/util/error.h"
#include "common/util/stopwatch.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;

/// Smallest distance from the origin to a triangle's plane: the faceted sphere lies in the
/// shell r_min <= |x| <= 1, so |signed distance - (1 - |p|)| <= 1 - r_min for every p.
double smallest_plane_distance(const TriangleSurface& s) {
  double r_min = std::numeric_limits<double>::infinity();
  for (const Triangle& tri : s.triangles) {
    const Vector3d a = s.vertices.col(tri[0]);
    const Vector3d n = (s.vertices.col(tri[1]) - a).cross(s.vertices.col(tri[2]) - a).normalized();
    r_min = std::min(r_min, std::abs(n.dot(a)));
  }
  return r_min;
}

/// `count` points at radii drawn uniformly from [r0, r1], in random directions.
Eigen::Matrix3Xd points_in_shell(int count, double r0, double r1, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> radius(r0, r1);
  Eigen::Matrix3Xd points(3, count);
  for (int i = 0; i < count; ++i) points.col(i) = radius(rng) * testing::random_direction(rng);
  return points;
}

Obstacle surface_obstacle(const std::string& name, TriangleSurface surface) {
  return Obstacle{name, std::move(surface), std::nullopt};
}

TEST(ObstacleDistance, PlaneGivesAnalyticSignedDistanceClosestPointAndNormal) {
  const Vector3d point(0.1, -0.2, 0.3);
  const Vector3d normal = Vector3d(2, -1, 2) / 3;
  const ObstacleDistance plane(Obstacle{"table", {}, std::make_pair(point, normal)},
                               Eigen::Matrix3Xd());
  EXPECT_TRUE(plane.is_plane());
  EXPECT_EQ(plane.name(), "table");
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> coordinate(-3, 3);
  for (int i = 0; i < 200; ++i) {
    const Vector3d p(coordinate(rng), coordinate(rng), coordinate(rng));
    // Written out: n . (p - x0) with n = (2, -1, 2) / 3.
    const double expected = (2 * (p.x() - 0.1) - (p.y() + 0.2) + 2 * (p.z() - 0.3)) / 3;
    EXPECT_NEAR(plane.signed_distance(p), expected, 1e-14);
    const ObstaclePoint c = plane.closest_point(p);
    EXPECT_NEAR(c.signed_distance, expected, 1e-14);
    EXPECT_NEAR((c.point - point).dot(normal), 0.0, 1e-14);
    EXPECT_LT((c.point + expected * normal - p).norm(), 1e-14);
    EXPECT_LT((c.normal - normal).norm(), 1e-15);
    EXPECT_EQ(c.triangle, -1);
  }
  // A normal that is not unit is normalised; the allowed side is still where it points.
  const ObstacleDistance floor(
      Obstacle{"floor", {}, std::make_pair(Vector3d::Zero(), Vector3d(0, 0, 5))},
      Eigen::Matrix3Xd());
  EXPECT_DOUBLE_EQ(floor.signed_distance(Vector3d(4, 5, 0.25)), 0.25);
  EXPECT_DOUBLE_EQ(floor.signed_distance(Vector3d(4, 5, -0.5)), -0.5);
}

/// Faceted unit sphere: the signed distance is 1 - |p| (allowed inside) or |p| - 1
/// (allowed outside) within the faceting error, with the right sign off the shell, and
/// p = point + signed_distance * normal.
void expect_sphere_distances(const ObstacleDistance& sphere, double r_min, bool allowed_inside) {
  const double facet_error = 1 - r_min;
  const Eigen::Matrix3Xd points = points_in_shell(3000, 0.0, 2.5, 99);
  const double sign = allowed_inside ? 1 : -1;
  double worst_error = 0, worst_normal_cosine = 1;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Vector3d p = points.col(i);
    const double r = p.norm();
    SCOPED_TRACE(::testing::Message() << "p = " << p.transpose() << ", |p| = " << r);
    const double s = sphere.signed_distance(p);
    EXPECT_LE(std::abs(s - sign * (1 - r)), facet_error + 1e-12);
    worst_error = std::max(worst_error, std::abs(s - sign * (1 - r)));
    if (r < r_min - 1e-9) {
      EXPECT_GT(sign * s, 0.0);
    }
    if (r > 1 + 1e-9) {
      EXPECT_LT(sign * s, 0.0);
    }
    const ObstaclePoint c = sphere.closest_point(p);
    EXPECT_EQ(c.signed_distance, s);
    EXPECT_GE(c.triangle, 0);
    EXPECT_GE(c.point.norm(), r_min - 1e-12);
    EXPECT_LE(c.point.norm(), 1 + 1e-12);
    EXPECT_NEAR(c.normal.norm(), 1.0, 1e-12);
    EXPECT_LT((c.point + s * c.normal - p).norm(), 1e-12);
    if (r > 1.2) {
      // Well outside, the normal towards the allowed side is nearly radial.
      const double cosine = c.normal.dot(-sign * p / r);
      EXPECT_GT(cosine, 0.95);
      worst_normal_cosine = std::min(worst_normal_cosine, cosine);
    }
  }
  std::printf(
      "[ icosphere ] faceting bound 1 - r_min = %.6f, largest |error| %.6f, smallest normal cosine "
      "%.6f\n",
      facet_error, worst_error, worst_normal_cosine);
}

TEST(ObstacleDistance, ClosedSurfaceWithObjectInsideAllowsInside) {
  const TriangleSurface sphere = testing::make_icosphere(3, 1.0);
  const double r_min = smallest_plane_distance(sphere);
  ASSERT_GT(r_min, 0.99);  // level 3: the faceting error is a few thousandths
  const ObstacleDistance obstacle(surface_obstacle("ball", sphere),
                                  points_in_shell(200, 0.1, 0.9, 1));
  EXPECT_TRUE(obstacle.is_closed());
  EXPECT_FALSE(obstacle.is_plane());
  EXPECT_TRUE(obstacle.allowed_inside());
  EXPECT_GT(obstacle.signed_distance(Vector3d::Zero()), 0.99);
  expect_sphere_distances(obstacle, r_min, true);
}

TEST(ObstacleDistance, ClosedSurfaceWithObjectOutsideAllowsOutside) {
  const TriangleSurface sphere = testing::make_icosphere(3, 1.0);
  const double r_min = smallest_plane_distance(sphere);
  const ObstacleDistance obstacle(surface_obstacle("ball", sphere),
                                  points_in_shell(200, 1.5, 3.0, 2));
  EXPECT_FALSE(obstacle.allowed_inside());
  EXPECT_LT(obstacle.signed_distance(Vector3d::Zero()), -0.99);
  expect_sphere_distances(obstacle, r_min, false);
}

TEST(ObstacleDistance, TriangleOrientationDoesNotMatter) {
  const TriangleSurface outward = testing::make_icosphere(2, 1.0);
  TriangleSurface inward = outward;
  for (Triangle& tri : inward.triangles) std::swap(tri[1], tri[2]);
  const Eigen::Matrix3Xd inside = points_in_shell(100, 0.0, 0.8, 3);
  const ObstacleDistance a(surface_obstacle("outward", outward), inside);
  const ObstacleDistance b(surface_obstacle("inward", inward), inside);
  EXPECT_TRUE(a.allowed_inside());
  EXPECT_TRUE(b.allowed_inside());
  const Eigen::Matrix3Xd points = points_in_shell(1000, 0.0, 2.0, 4);
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Vector3d p = points.col(i);
    const ObstaclePoint pa = a.closest_point(p), pb = b.closest_point(p);
    EXPECT_NEAR(pa.signed_distance, pb.signed_distance, 1e-14) << p.transpose();
    EXPECT_LT((pa.normal - pb.normal).norm(), 1e-10) << p.transpose();
  }
}

TEST(ObstacleDistance, ObjectOnBothSidesIsAnErrorNamingTheSplit) {
  Eigen::Matrix3Xd reference(3, 100);
  reference.leftCols(62) = points_in_shell(62, 0.2, 0.8, 5);
  reference.rightCols(38) = points_in_shell(38, 1.5, 2.0, 6);
  try {
    const ObstacleDistance obstacle(surface_obstacle("skull", testing::make_icosphere(2, 1.0)),
                                    reference);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "the object is not on one side of obstacle 'skull': 62 % inside, 38 % outside");
  }
  // 90 % on one side is enough.
  reference.leftCols(90) = points_in_shell(90, 1.5, 2.0, 7);
  reference.rightCols(10) = points_in_shell(10, 0.2, 0.8, 8);
  EXPECT_FALSE(
      ObstacleDistance(surface_obstacle("skull", testing::make_icosphere(2, 1.0)), reference)
          .allowed_inside());
}

TEST(ObstacleDistance, ConstructionErrorsNameTheObstacle) {
  const auto message = [](const Obstacle& obstacle,
                          const Eigen::Matrix3Xd& reference) -> std::string {
    try {
      ObstacleDistance distance(obstacle, reference);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  };
  const Eigen::Matrix3Xd one = Eigen::Matrix3Xd::Zero(3, 1);
  EXPECT_THAT(message(Obstacle{"nothing", {}, std::nullopt}, one),
              ::testing::HasSubstr("'nothing'"));
  EXPECT_THAT(
      message(Obstacle{"flat", {}, std::make_pair(Vector3d::Zero(), Vector3d::Zero())}, one),
      ::testing::HasSubstr("'flat'"));
  EXPECT_THAT(
      message(surface_obstacle("ball", testing::make_icosphere(1, 1.0)), Eigen::Matrix3Xd()),
      ::testing::HasSubstr("'ball': no reference points"));
}

TEST(ObstacleDistance, OpenSurfaceUsesFaceNormalsBeyondItsRim) {
  TriangleSurface square;
  square.vertices.resize(3, 4);
  square.vertices << -1, 1, 1, -1,  //
      -1, -1, 1, 1,                 //
      0, 0, 0, 0;
  square.triangles = {{0, 1, 2}, {0, 2, 3}};  // facing +z
  Eigen::Matrix3Xd above(3, 2);
  above << 0, 0.3, 0, 0.2, 0.5, 1;
  const ObstacleDistance sheet(surface_obstacle("sheet", square), above);
  EXPECT_FALSE(sheet.is_closed());
  EXPECT_FALSE(sheet.allowed_inside());  // in front of the triangles
  EXPECT_DOUBLE_EQ(sheet.signed_distance(Vector3d(0.2, 0.3, 0.4)), 0.4);
  EXPECT_DOUBLE_EQ(sheet.signed_distance(Vector3d(0.2, 0.3, -0.4)), -0.4);
  EXPECT_DOUBLE_EQ(sheet.signed_distance(Vector3d(0.1, 0.1, 0.3)),
                   0.3);  // above the shared diagonal
  // Beyond the rim edge x = 1: distance to the edge, sign from the face normal.
  EXPECT_DOUBLE_EQ(sheet.signed_distance(Vector3d(2, 0, 0.5)), std::sqrt(1.25));
  EXPECT_DOUBLE_EQ(sheet.signed_distance(Vector3d(2, 0, -0.5)), -std::sqrt(1.25));
  // Beyond the corner (1, 1, 0).
  EXPECT_DOUBLE_EQ(sheet.signed_distance(Vector3d(2, 3, 0.5)), std::sqrt(1 + 4 + 0.25));
  EXPECT_DOUBLE_EQ(sheet.signed_distance(Vector3d(2, 3, -0.5)), -std::sqrt(1 + 4 + 0.25));
  const ObstaclePoint c = sheet.closest_point(Vector3d(2, 0, -0.5));
  EXPECT_LT((c.point - Vector3d(1, 0, 0)).norm(), 1e-15);
  EXPECT_LT((c.normal - Vector3d(-1, 0, 0.5).normalized()).norm(),
            1e-15);  // towards the allowed side
  // On the surface: the pseudo-normal.
  const ObstaclePoint on = sheet.closest_point(Vector3d(0.5, -0.25, 0));
  EXPECT_EQ(on.signed_distance, 0.0);
  EXPECT_EQ(on.normal, Vector3d(0, 0, 1));
}

/// Colin27 data shipped beside the project (../shared/data/colin27), in millimetres.
std::filesystem::path colin27(const std::string& name) {
  const std::filesystem::path beside = testing::source_path("../shared/data/colin27/" + name);
  if (std::filesystem::exists(beside)) return beside;
  return std::filesystem::path("/work/shared/data/colin27") / name;
}

TEST(ObstacleDistance, Colin27InnerSkullContainsTheBrain) {
  const auto skull_file = colin27("inner_skull_surface.asc"),
             brain_file = colin27("brain_surface.asc");
  if (!std::filesystem::exists(skull_file) || !std::filesystem::exists(brain_file))
    GTEST_SKIP() << "Colin27 surfaces not found at " << skull_file.parent_path();
  const TriangleSurface skull = read_freesurfer_ascii(skull_file);
  const TriangleSurface brain = read_freesurfer_ascii(brain_file);
  Stopwatch build_clock;
  const ObstacleDistance obstacle(surface_obstacle("inner skull", skull), brain.vertices);
  const double build_ms = build_clock.elapsed_ms();
  EXPECT_TRUE(obstacle.allowed_inside());

  int positive = 0, within_1mm = 0, within_3mm = 0;
  double smallest = std::numeric_limits<double>::infinity();
  for (int v = 0; v < brain.vertex_count(); ++v) {
    const double s = obstacle.signed_distance(brain.vertices.col(v));
    positive += s > 0;
    within_1mm += s < 1;
    within_3mm += s < 3;
    smallest = std::min(smallest, s);
  }
  const int n = brain.vertex_count();
  EXPECT_GE(positive, static_cast<int>(std::ceil(0.99 * n)));
  std::printf(
      "[ Colin27 ] skull %d triangles (%s), built in %.1f ms; brain %d vertices: %d on the allowed "
      "side, %d within "
      "1 mm, %d within 3 mm, smallest signed distance %.3f mm\n",
      skull.triangle_count(), obstacle.is_closed() ? "closed" : "open", build_ms, n, positive,
      within_1mm, within_3mm, smallest);

  // Far outside the skull is forbidden; the brain's centre is allowed.
  const Vector3d centre = brain.vertices.rowwise().mean();
  EXPECT_GT(obstacle.signed_distance(centre), 0.0);
  for (const Vector3d& offset : {Vector3d(300, 0, 0), Vector3d(0, -300, 0), Vector3d(0, 0, 300)})
    EXPECT_LT(obstacle.signed_distance(centre + offset), 0.0);

  // Distances against a linear scan over every skull triangle, and timing of both.
  std::mt19937 rng(27);
  const Vector3d lo = skull.vertices.rowwise().minCoeff().array() - 10;
  const Vector3d hi = skull.vertices.rowwise().maxCoeff().array() + 10;
  std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y()), uz(lo.z(), hi.z());
  std::vector<Vector3d> points(20000);
  for (Vector3d& p : points) p = Vector3d(ux(rng), uy(rng), uz(rng));
  const int scanned = 200;
  std::vector<double> scan_distance(scanned);
  Stopwatch scan_clock;
  for (int i = 0; i < scanned; ++i) {
    double best2 = std::numeric_limits<double>::infinity();
    for (const Triangle& tri : skull.triangles) {
      const TriangleClosestPoint q =
          closest_point_on_triangle(points[i], skull.vertices.col(tri[0]),
                                    skull.vertices.col(tri[1]), skull.vertices.col(tri[2]));
      best2 = std::min(best2, (points[i] - q.point).squaredNorm());
    }
    scan_distance[i] = std::sqrt(best2);
  }
  const double scan_ms = scan_clock.elapsed_ms();
  for (int i = 0; i < scanned; ++i)
    EXPECT_NEAR(std::abs(obstacle.signed_distance(points[i])), scan_distance[i],
                1e-12 * scan_distance[i]);

  double sink = 0;
  Stopwatch tree_clock;
  for (const Vector3d& p : points) sink += obstacle.signed_distance(p);
  const double tree_ms = tree_clock.elapsed_ms();
  Stopwatch near_clock;
  for (int v = 0; v < n; ++v) sink += obstacle.signed_distance(brain.vertices.col(v));
  const double near_ms = near_clock.elapsed_ms();
  std::printf(
      "[ Colin27 ] signed distance: %.0f queries/s (random in the skull's box), %.0f queries/s "
      "(brain vertices); "
      "linear scan %.0f queries/s (checksum %.3g)\n",
      1e3 * static_cast<double>(points.size()) / tree_ms, 1e3 * n / near_ms,
      1e3 * scanned / scan_ms, sink);
}

}  // namespace
}  // namespace cohaptic
