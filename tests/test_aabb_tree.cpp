// AabbTree (common/contact/aabb_tree.h): every answer is compared with a linear scan over
// all triangles (the same closest-point routine, no tree), on a radially perturbed
// icosphere, on the boundary of a box mesh (many coplanar triangles and exact ties), and on
// a soup of random triangles including degenerate ones; plus reach limits, the empty tree
// and the depth the median split promises.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "support/test_meshes.h"
#include "common/contact/aabb_tree.h"
#include "common/contact/closest_point_on_triangle.h"
#include "common/mesh/boundary_surface.h"
#include "common/mesh/box_mesher.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;

struct Scan {
  int triangle = -1;
  double distance2 = std::numeric_limits<double>::infinity();
};

/// The reference: first triangle at the smallest distance, by a linear scan.
Scan linear_scan(const Eigen::Matrix3Xd& vertices, const std::vector<Triangle>& triangles,
                 const Vector3d& p) {
  Scan best;
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    const Triangle& tri = triangles[t];
    const TriangleClosestPoint q = closest_point_on_triangle(
        p, vertices.col(tri[0]), vertices.col(tri[1]), vertices.col(tri[2]));
    const double d2 = (p - q.point).squaredNorm();
    if (d2 < best.distance2) best = {t, d2};
  }
  return best;
}

double distance_to(const Eigen::Matrix3Xd& vertices, const Triangle& tri, const Vector3d& p) {
  return (p - closest_point_on_triangle(p, vertices.col(tri[0]), vertices.col(tri[1]),
                                        vertices.col(tri[2]))
                  .point)
      .norm();
}

/// Checks every point against the linear scan: same distance to 1e-14 relative, and the
/// same triangle unless the tree's triangle is (to 1e-14) just as close. Returns how many
/// triangles differed (ties).
int expect_matches_linear_scan(const AabbTree& tree, const Eigen::Matrix3Xd& vertices,
                               const std::vector<Triangle>& triangles,
                               const std::vector<Vector3d>& points) {
  int ties = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vector3d& p = points[i];
    SCOPED_TRACE(::testing::Message() << "point " << i << " at " << p.transpose());
    const AabbHit hit = tree.closest_triangle(p);
    const Scan reference = linear_scan(vertices, triangles, p);
    EXPECT_GE(hit.triangle, 0);
    if (hit.triangle < 0) continue;
    const double expected = std::sqrt(reference.distance2);
    const double tolerance = 1e-14 * std::max(expected, 1e-300);
    EXPECT_NEAR(std::sqrt(hit.distance2), expected, tolerance);
    // The point returned belongs to the triangle reported (index mapping back to the input).
    const Triangle& tri = triangles[hit.triangle];
    const TriangleClosestPoint q = closest_point_on_triangle(
        p, vertices.col(tri[0]), vertices.col(tri[1]), vertices.col(tri[2]));
    EXPECT_EQ(hit.closest.point, q.point);
    EXPECT_EQ(hit.closest.weights, q.weights);
    if (hit.triangle != reference.triangle) {
      ++ties;
      EXPECT_NEAR(distance_to(vertices, tri, p), expected, tolerance)
          << "tree " << hit.triangle << " scan " << reference.triangle;
    }
  }
  return ties;
}

TEST(AabbTree, MatchesLinearScanOnPerturbedIcosphere) {
  TriangleSurface surface = testing::make_icosphere(3, 1.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> bump(0.85, 1.15);
  for (Eigen::Index v = 0; v < surface.vertices.cols(); ++v) surface.vertices.col(v) *= bump(rng);
  const AabbTree tree(surface);
  ASSERT_EQ(tree.triangle_count(), 1280);

  std::vector<Vector3d> points;
  std::uniform_real_distribution<double> box(-2, 2), shell(0.8, 1.2), far(2, 20);
  for (int i = 0; i < 1000; ++i) points.emplace_back(box(rng), box(rng), box(rng));
  for (int i = 0; i < 1000; ++i) points.push_back(shell(rng) * testing::random_direction(rng));
  for (int i = 0; i < 300; ++i) points.push_back(far(rng) * testing::random_direction(rng));
  // Exactly at vertices and edge midpoints, where several triangles tie.
  for (Eigen::Index v = 0; v < surface.vertices.cols(); v += 7)
    points.push_back(surface.vertices.col(v));
  for (int t = 0; t < surface.triangle_count(); t += 11) {
    const Triangle& tri = surface.triangles[t];
    points.push_back(1.01 * (surface.vertices.col(tri[0]) + surface.vertices.col(tri[1])) / 2);
  }
  const int ties = expect_matches_linear_scan(tree, surface.vertices, surface.triangles, points);
  std::printf(
      "[ perturbed icosphere ] %zu points, %d resolved to another triangle at the same distance\n",
      points.size(), ties);
}

TEST(AabbTree, MatchesLinearScanOnBoxSurface) {
  const TetMesh mesh =
      make_box_mesh(Vector3d(-0.2, 0.1, 0.3), Vector3d(1.0, 2.0, 0.5), Eigen::Vector3i(4, 6, 3));
  const BoundarySurface boundary = extract_boundary_surface(mesh);
  // Over the volume nodes directly: interior nodes are simply unused.
  const AabbTree tree(mesh.nodes, boundary.triangles);
  ASSERT_EQ(tree.triangle_count(), boundary.triangle_count());

  std::mt19937 rng(11);
  std::uniform_real_distribution<double> x(-1, 1.6), y(-0.7, 2.9), z(-0.5, 1.6);
  std::uniform_int_distribution<int> grid(-4, 12);
  std::vector<Vector3d> points;
  for (int i = 0; i < 2000; ++i) points.emplace_back(x(rng), y(rng), z(rng));
  // On a lattice aligned with the box faces and nodes: many exact ties.
  for (int i = 0; i < 500; ++i)
    points.emplace_back(0.125 * grid(rng), 0.25 * grid(rng), 0.125 * grid(rng));
  const int ties = expect_matches_linear_scan(tree, mesh.nodes, boundary.triangles, points);
  std::printf(
      "[ box surface ] %d triangles, %zu points, %d resolved to another triangle at the same "
      "distance\n",
      boundary.triangle_count(), points.size(), ties);
}

TEST(AabbTree, MatchesLinearScanOnTriangleSoupWithDegenerateTriangles) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-1, 1), small(-0.1, 0.1);
  const int n = 600;
  Eigen::Matrix3Xd vertices(3, 3 * n);
  std::vector<Triangle> triangles;
  for (int t = 0; t < n; ++t) {
    const Vector3d a(coordinate(rng), coordinate(rng), coordinate(rng));
    const Vector3d b = a + Vector3d(small(rng), small(rng), small(rng));
    Vector3d c = a + Vector3d(small(rng), small(rng), small(rng));
    if (t % 10 == 0) c = a + 0.3 * (b - a);  // collinear
    if (t % 10 == 1) c = b;                  // two equal corners
    vertices.col(3 * t) = a;
    vertices.col(3 * t + 1) = b;
    vertices.col(3 * t + 2) = c;
    triangles.push_back({3 * t, 3 * t + 1, 3 * t + 2});
  }
  const AabbTree tree(vertices, triangles);
  std::vector<Vector3d> points;
  std::uniform_real_distribution<double> box(-1.5, 1.5);
  for (int i = 0; i < 2000; ++i) points.emplace_back(box(rng), box(rng), box(rng));
  expect_matches_linear_scan(tree, vertices, triangles, points);
}

TEST(AabbTree, FindsNothingBeyondMaxDistance) {
  const TriangleSurface surface = testing::make_icosphere(2, 1.0);
  const AabbTree tree(surface);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> radius(0.2, 4);
  for (int i = 0; i < 500; ++i) {
    const Vector3d p = radius(rng) * testing::random_direction(rng);
    const Scan reference = linear_scan(surface.vertices, surface.triangles, p);
    const double d = std::sqrt(reference.distance2);
    const AabbHit short_reach = tree.closest_triangle(p, 0.999 * d);
    EXPECT_EQ(short_reach.triangle, -1) << p.transpose();
    EXPECT_EQ(short_reach.distance2, std::numeric_limits<double>::infinity());
    const AabbHit long_reach = tree.closest_triangle(p, 1.001 * d);
    EXPECT_EQ(long_reach.triangle, tree.closest_triangle(p).triangle) << p.transpose();
    EXPECT_NEAR(std::sqrt(long_reach.distance2), d, 1e-14 * d);
  }
  EXPECT_EQ(tree.closest_triangle(Vector3d(0, 0, 5), -1.0).triangle, -1);
}

TEST(AabbTree, EmptySurfaceFindsNothing) {
  const AabbTree by_default;
  EXPECT_EQ(by_default.closest_triangle(Vector3d(1, 2, 3)).triangle, -1);
  const AabbTree from_empty(TriangleSurface{});
  const AabbHit hit = from_empty.closest_triangle(Vector3d::Zero());
  EXPECT_EQ(hit.triangle, -1);
  EXPECT_EQ(hit.distance2, std::numeric_limits<double>::infinity());
  EXPECT_EQ(from_empty.node_count(), 0);
  EXPECT_EQ(from_empty.depth(), 0);
  const AabbTree vertices_only(Eigen::Matrix3Xd::Random(3, 5), std::vector<Triangle>{});
  EXPECT_EQ(vertices_only.closest_triangle(Vector3d::Zero()).triangle, -1);
}

TEST(AabbTree, SingleTriangleIsOneLeaf) {
  Eigen::Matrix3Xd vertices(3, 3);
  vertices << 0, 1, 0, 0, 0, 1, 0, 0, 0;
  const AabbTree tree(vertices, std::vector<Triangle>{{0, 1, 2}});
  EXPECT_EQ(tree.node_count(), 1);
  EXPECT_EQ(tree.depth(), 1);
  const AabbHit hit = tree.closest_triangle(Vector3d(0.25, 0.25, 2));
  EXPECT_EQ(hit.triangle, 0);
  EXPECT_DOUBLE_EQ(hit.distance2, 4.0);
  EXPECT_EQ(hit.closest.point, Vector3d(0.25, 0.25, 0));
}

TEST(AabbTree, DepthIsLogarithmic) {
  for (int level = 0; level <= 5; ++level) {
    const TriangleSurface surface = testing::make_icosphere(level, 1.0);
    const AabbTree tree(surface);
    const int n = surface.triangle_count();
    // Median split: level L holds ranges of at most ceil(n / 2^L) triangles.
    int expected = 1;
    for (int size = n; size > AabbTree::kLeafSize; size = (size + 1) / 2) ++expected;
    EXPECT_EQ(tree.depth(), expected) << n << " triangles";
    EXPECT_LE(tree.node_count(), 2 * ((n + AabbTree::kLeafSize - 1) / AabbTree::kLeafSize) * 2)
        << n;
  }
}

TEST(AabbTree, RejectsBadIndicesAndNonFiniteVertices) {
  Eigen::Matrix3Xd vertices = Eigen::Matrix3Xd::Zero(3, 3);
  vertices(0, 1) = 1;
  vertices(1, 2) = 1;
  EXPECT_THROW(AabbTree(vertices, std::vector<Triangle>{{0, 1, 3}}), Error);
  EXPECT_THROW(AabbTree(vertices, std::vector<Triangle>{{-1, 1, 2}}), Error);
  vertices(2, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(AabbTree(vertices, std::vector<Triangle>{{0, 1, 2}}), Error);
}

}  // namespace
}  // namespace cohaptic
