// Pairs of nearest nodes: the update of pairs (walking a passive node along its surface
// to a nearer neighbour) finds the nearest surface node that brute force finds, for
// active nodes that move across an icosphere from random starting pairs; the addition
// of pairs pairs every unpaired surface neighbour of a colliding node, and only those.
#include <gtest/gtest.h>

#include <numeric>
#include <random>

#include "common/interaction/node_pairs.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

int brute_force_nearest(const Eigen::Vector3d& point, const Eigen::Matrix3Xd& positions) {
  Eigen::Index nearest = 0;
  (positions.colwise() - point).colwise().squaredNorm().minCoeff(&nearest);
  return static_cast<int>(nearest);
}

TEST(InteractionPairs, UpdateWalksToTheNearestNodeOfBruteForce) {
  const TriangleSurface sphere = testing::make_icosphere(3, 0.05);
  const SurfaceAdjacency surface = make_surface_adjacency(sphere.triangles, sphere.vertex_count());
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> any_node(0, sphere.vertex_count() - 1);
  std::uniform_real_distribution<double> radius(0.045, 0.06);
  Eigen::Matrix3Xd active(3, 200);
  for (Eigen::Index i = 0; i < active.cols(); ++i)
    active.col(i) = radius(rng) * testing::random_direction(rng);
  std::vector<int> active_nodes(200);
  std::iota(active_nodes.begin(), active_nodes.end(), 0);
  NodePairList list;
  list.paired.assign(200, 1);
  for (int node : active_nodes)
    list.pairs.push_back({node, any_node(rng)});  // far from nearest, on purpose
  for (int step = 0; step < 5; ++step) {
    update_node_pairs(list, active, sphere.vertices, surface);
    for (const NodePair& pair : list.pairs)
      EXPECT_EQ(pair.passive, brute_force_nearest(active.col(pair.active), sphere.vertices))
          << "step " << step;
    for (Eigen::Index i = 0; i < active.cols(); ++i)
      active.col(i) += 0.004 * testing::random_direction(rng);
  }
}

TEST(InteractionPairs, AdditionPairsTheUnpairedNeighboursOfCollidingNodes) {
  const TriangleSurface sphere = testing::make_icosphere(2, 0.05);
  const SurfaceAdjacency surface = make_surface_adjacency(sphere.triangles, sphere.vertex_count());
  // The active body is a second sphere, slightly larger: nodes pair across.
  const Eigen::Matrix3Xd active = 1.02 * sphere.vertices;
  const int first = 0, second = 5;
  const std::vector<int> seeds{first, second};
  NodePairList list = make_node_pairs(seeds, active, std::vector<int>{0, 1, 2, 3}, sphere.vertices);
  const std::vector<int> colliding{0};  // the pair of node `first`
  const int added = add_neighbour_pairs(list, colliding, active, surface, sphere.vertices, surface);
  std::vector<int> expected;
  for (int n : surface.neighbours(first))
    if (n != second) expected.push_back(n);
  ASSERT_EQ(added, static_cast<int>(expected.size()));
  for (std::size_t k = 0; k < expected.size(); ++k) {
    const NodePair& pair = list.pairs[2 + k];
    EXPECT_EQ(pair.active, expected[k]);
    EXPECT_EQ(pair.passive, brute_force_nearest(active.col(pair.active), sphere.vertices));
    EXPECT_TRUE(list.paired[static_cast<std::size_t>(pair.active)]);
  }
  // Again: nothing new.
  EXPECT_EQ(add_neighbour_pairs(list, colliding, active, surface, sphere.vertices, surface), 0);
}

}  // namespace
}  // namespace cohaptic
