// order_in_compact_groups (common/mesh/compact_groups.h): a permutation of the ids it is
// given; on the brain's surface nodes, its groups of 16 are several times smaller than the
// file order's, and the nodes near a surface point fall into fewer groups (what a patch or
// an approaching tool costs in compliance solves); bad input is named.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <set>

#include "common/mesh/boundary_surface.h"
#include "common/mesh/compact_groups.h"
#include "common/mesh/read_gmsh.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

constexpr int kGroup = 16;

double mean_group_diagonal(const Eigen::Matrix3Xd& positions, const std::vector<int>& order) {
  double sum = 0;
  int groups = 0;
  for (std::size_t first = 0; first < order.size(); first += kGroup, ++groups) {
    Eigen::Vector3d lo = positions.col(order[first]), hi = lo;
    for (std::size_t k = first; k < std::min(order.size(), first + kGroup); ++k) {
      lo = lo.cwiseMin(positions.col(order[k]));
      hi = hi.cwiseMax(positions.col(order[k]));
    }
    sum += (hi - lo).norm();
  }
  return sum / groups;
}

// Mean number of groups that hold the nodes within `radius` of each node.
double mean_groups_near(const Eigen::Matrix3Xd& positions, const std::vector<int>& order,
                        double radius) {
  double sum = 0;
  for (int centre : order) {
    std::set<std::size_t> groups;
    for (std::size_t k = 0; k < order.size(); ++k)
      if ((positions.col(order[k]) - positions.col(centre)).norm() <= radius)
        groups.insert(k / kGroup);
    sum += static_cast<double>(groups.size());
  }
  return sum / static_cast<double>(order.size());
}

TEST(CompactGroups, BrainSurfaceNodesFallIntoFewerSmallerGroups) {
  const TetMesh mesh =
      read_gmsh(std::filesystem::path(COHAPTIC_SOURCE_DIR) / "scenes/brain/brain.msh").mesh;
  const std::vector<int> file_order = extract_boundary_surface(mesh).nodes;
  const std::vector<int> compact = order_in_compact_groups(mesh.nodes, file_order, kGroup);
  std::vector<int> a = file_order, b = compact;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  ASSERT_EQ(a, b) << "not a permutation of the ids given";

  const double file_diagonal = mean_group_diagonal(mesh.nodes, file_order);
  const double compact_diagonal = mean_group_diagonal(mesh.nodes, compact);
  const double file_groups = mean_groups_near(mesh.nodes, file_order, 10.0);
  const double compact_groups = mean_groups_near(mesh.nodes, compact, 10.0);
  std::printf(
      "  %zu nodes: group diagonal %.1f mm (file order %.1f mm); nodes within 10 mm in %.2f groups "
      "(%.2f)\n",
      file_order.size(), compact_diagonal, file_diagonal, compact_groups, file_groups);
  EXPECT_LT(compact_diagonal, 0.5 * file_diagonal);
  EXPECT_LT(compact_groups, 0.5 * file_groups);
}

TEST(CompactGroups, TiesGoByIdAndBadInputIsNamed) {
  const Eigen::Matrix3Xd positions =
      Eigen::Matrix3Xd::Zero(3, 40);  // all coincident: every split goes by id
  std::vector<int> ids(40);
  for (int i = 0; i < 40; ++i) ids[static_cast<std::size_t>(i)] = 39 - i;
  const std::vector<int> order = order_in_compact_groups(positions, ids, kGroup);
  for (std::size_t k = 0; k < order.size(); ++k)
    EXPECT_EQ(static_cast<std::size_t>(order[k]) / kGroup, k / kGroup)
        << "id " << order[k] << " at " << k;
  EXPECT_THROW(order_in_compact_groups(positions, {40}, kGroup), Error);
  EXPECT_THROW(order_in_compact_groups(positions, ids, 0), Error);
}

}  // namespace
}  // namespace cohaptic
