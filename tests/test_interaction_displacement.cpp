// Forcible displacement of passive polygons: after it, every active node lies on its
// displaced polygon (1e-9 m); one polygon follows the paper's balance rule
// u_k = w_k / sum w^2 (P - T); several polygons sharing nodes get the smallest
// displacement that meets every condition, checked against the KKT system of that
// least-norm problem solved by dense LU; a fixed axis does not move; two contradicting
// conditions are met in the least-squares sense.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <numeric>
#include <random>

#include "common/interaction/forcible_displacement.h"

namespace cohaptic {
namespace {

// A flat grid of n x n nodes in z = 0 (spacing 1), two triangles per cell.
struct Grid {
  int n = 6;
  Eigen::Matrix3Xd positions;
  std::vector<Triangle> triangles;
  explicit Grid(int size) : n(size), positions(3, size * size) {
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) positions.col(j * n + i) = Eigen::Vector3d(i, j, 0);
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        const int a = j * n + i;
        triangles.push_back({a, a + 1, a + n + 1});
        triangles.push_back({a, a + n + 1, a + n});
      }
  }
};

// A collision of an active node at `active` with triangle `t` at barycentric `weights`.
PolygonCollision collision_at(const Grid& grid, int t, const Eigen::Vector3d& weights,
                              const Eigen::Vector3d& active) {
  PolygonCollision c;
  c.active = t;
  c.polygon = grid.triangles[static_cast<std::size_t>(t)];
  c.weights = weights;
  for (int k = 0; k < 3; ++k)
    c.target += weights[k] * grid.positions.col(c.polygon[static_cast<std::size_t>(k)]);
  c.gap = active - c.target;
  return c;
}

Eigen::Vector3d displaced_target(const Grid& grid, const PolygonCollision& c,
                                 const ForcibleDisplacement& d) {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < 3; ++k) {
    const auto j = std::lower_bound(d.nodes.begin(), d.nodes.end(), c.polygon[k]) - d.nodes.begin();
    point += c.weights[static_cast<Eigen::Index>(k)] *
             (grid.positions.col(c.polygon[k]) + d.displacement.segment<3>(3 * j));
  }
  return point;
}

Eigen::Vector3d random_weights(std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.05, 1);
  Eigen::Vector3d w(unit(rng), unit(rng), unit(rng));
  return w / w.sum();
}

TEST(InteractionDisplacement, OnePolygonFollowsTheBalanceRule) {
  const Grid grid(3);
  const std::vector<AxisMask> free_axes(9, 0);
  const Eigen::Vector3d weights(0.6, 0.3, 0.1);
  const PolygonCollision c = collision_at(grid, 2, weights, Eigen::Vector3d(1.5, 0.4, 0.02));
  const ForcibleDisplacement d = forcible_displacement(std::span(&c, 1), free_axes);
  ASSERT_EQ(d.nodes.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    const auto j = std::lower_bound(d.nodes.begin(), d.nodes.end(), c.polygon[k]) - d.nodes.begin();
    const Eigen::Vector3d expected =
        weights[static_cast<Eigen::Index>(k)] / weights.squaredNorm() * c.gap;
    EXPECT_LT((d.displacement.segment<3>(3 * j) - expected).norm(), 1e-15);
  }
  EXPECT_LT((displaced_target(grid, c, d) - (c.target + c.gap)).norm(), 1e-12);
}

TEST(InteractionDisplacement,
     ManyPolygonsSharingNodesPutEveryActiveNodeOnItsPolygonWithTheLeastDisplacement) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> depth(-0.05, 0.01), slide(-0.02, 0.02);
  const Grid grid(6);
  std::vector<AxisMask> fixed(36, 0);
  fixed[14] = 0b001;  // node 14 slides in y and z only
  for (int trial = 0; trial < 200; ++trial) {
    // Distinct triangles, several of them sharing nodes.
    std::vector<int> triangles(grid.triangles.size());
    std::iota(triangles.begin(), triangles.end(), 0);
    std::shuffle(triangles.begin(), triangles.end(), rng);
    std::vector<PolygonCollision> collisions;
    for (int k = 0; k < 1 + trial % 12; ++k) {
      const int t = triangles[static_cast<std::size_t>(k)];
      const Eigen::Vector3d weights = random_weights(rng);
      Eigen::Vector3d target = Eigen::Vector3d::Zero();
      for (std::size_t c = 0; c < 3; ++c)
        target += weights[static_cast<Eigen::Index>(c)] *
                  grid.positions.col(grid.triangles[static_cast<std::size_t>(t)][c]);
      collisions.push_back(collision_at(
          grid, t, weights, target + Eigen::Vector3d(slide(rng), slide(rng), depth(rng))));
    }
    const ForcibleDisplacement d = forcible_displacement(collisions, fixed);
    const auto n = static_cast<Eigen::Index>(d.nodes.size());
    const auto p = static_cast<Eigen::Index>(collisions.size());
    for (const PolygonCollision& c : collisions)
      EXPECT_LT((displaced_target(grid, c, d) - (c.target + c.gap)).norm(), 1e-9)
          << "trial " << trial;
    // The least-norm displacement per axis from its KKT system [I W^T; W 0] [u; l] = [0; r]
    // over the nodes free along that axis.
    for (int axis = 0; axis < 3; ++axis) {
      Eigen::MatrixXd w = Eigen::MatrixXd::Zero(p, n);
      for (Eigen::Index k = 0; k < p; ++k)
        for (std::size_t c = 0; c < 3; ++c) {
          const int node = collisions[static_cast<std::size_t>(k)].polygon[c];
          if ((fixed[static_cast<std::size_t>(node)] >> axis) & 1u) continue;
          w(k, std::lower_bound(d.nodes.begin(), d.nodes.end(), node) - d.nodes.begin()) +=
              collisions[static_cast<std::size_t>(k)].weights[static_cast<Eigen::Index>(c)];
        }
      Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(n + p, n + p);
      kkt.topLeftCorner(n, n).setIdentity();
      kkt.topRightCorner(n, p) = w.transpose();
      kkt.bottomLeftCorner(p, n) = w;
      Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n + p);
      for (Eigen::Index k = 0; k < p; ++k)
        rhs[n + k] = collisions[static_cast<std::size_t>(k)].gap[axis];
      const Eigen::VectorXd solution = kkt.fullPivLu().solve(rhs);
      for (Eigen::Index j = 0; j < n; ++j)
        EXPECT_NEAR(d.displacement[3 * j + axis], solution[j], 1e-12)
            << "trial " << trial << " axis " << axis;
    }
    // The fixed axis stays.
    const auto sliding = std::lower_bound(d.nodes.begin(), d.nodes.end(), 14);
    if (sliding != d.nodes.end() && *sliding == 14) {
      EXPECT_EQ(d.displacement[3 * (sliding - d.nodes.begin())], 0.0);
    }
  }
}

TEST(InteractionDisplacement, ContradictingConditionsAreMetInTheLeastSquaresSense) {
  const Grid grid(3);
  const std::vector<AxisMask> free_axes(9, 0);
  const Eigen::Vector3d weights(0.2, 0.5, 0.3);
  // Two active nodes ask the same point of one polygon to sink by 1 and by 3 cm.
  PolygonCollision first = collision_at(grid, 0, weights, Eigen::Vector3d::Zero());
  first.gap = Eigen::Vector3d(0, 0, -0.01);
  PolygonCollision second = first;
  second.gap = Eigen::Vector3d(0, 0, -0.03);
  const std::vector<PolygonCollision> collisions{first, second};
  const ForcibleDisplacement d = forcible_displacement(collisions, free_axes);
  EXPECT_LT(
      (displaced_target(grid, first, d) - (first.target + Eigen::Vector3d(0, 0, -0.02))).norm(),
      1e-12);
  EXPECT_TRUE(d.displacement.allFinite());
}

TEST(InteractionDisplacement, APolygonFixedAlongAnAxisDoesNotGiveWayAlongIt) {
  const Grid grid(3);
  std::vector<AxisMask> fixed(9, 0b100);  // z fixed everywhere: a rigid floor in z
  const PolygonCollision c =
      collision_at(grid, 0, Eigen::Vector3d(0.2, 0.5, 0.3), Eigen::Vector3d(0.5, 0.4, -0.01));
  const ForcibleDisplacement d = forcible_displacement(std::span(&c, 1), fixed);
  for (Eigen::Index j = 0; j < 3; ++j) EXPECT_EQ(d.displacement[3 * j + 2], 0.0);
  EXPECT_LT(
      (displaced_target(grid, c, d) - (c.target + Eigen::Vector3d(c.gap.x(), c.gap.y(), 0))).norm(),
      1e-12);
}

}  // namespace
}  // namespace cohaptic
