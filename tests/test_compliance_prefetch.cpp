// CompliancePrefetch (server/compliance_prefetch.h) on the paper's cube with rows over the
// whole surface: the columns its worker thread solves equal, bit for bit, those the
// simulation thread solves itself (the same group solves), which is what lets a session
// that prefetched replay bit for bit; request_near asks for exactly the groups of the row
// nodes within reach of the tool; deliver never replaces a column the caller has.
#include <gtest/gtest.h>

#include <chrono>
#include <set>
#include <thread>

#include "server/compliance_prefetch.h"
#include "support/cube_scene.h"

namespace cohaptic {
namespace {

// Delivers into `columns` until it holds `count` columns, or 60 s pass.
void deliver_until(CompliancePrefetch& prefetch, ComplianceColumns& columns, std::size_t count) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (columns.column_count() < count && std::chrono::steady_clock::now() < deadline) {
    prefetch.deliver(columns);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

// The row nodes whose groups hold a row node within `reach` of `point`.
std::set<int> nodes_of_groups_near(const ElasticBody& body, const ComplianceColumns& columns,
                                   const Eigen::Vector3d& point, double reach) {
  std::set<int> groups, nodes;
  const std::vector<int>& rows = columns.row_nodes();
  for (std::size_t r = 0; r < rows.size(); ++r)
    if ((body.mesh.nodes.col(rows[r]) - point).norm() < reach)
      groups.insert(ComplianceColumns::group_of(static_cast<int>(r)));
  for (std::size_t r = 0; r < rows.size(); ++r)
    if (groups.count(ComplianceColumns::group_of(static_cast<int>(r)))) nodes.insert(rows[r]);
  return nodes;
}

TEST(CompliancePrefetch, SolvesTheGroupsNearAToolBitForBitAsTheSimulationWould) {
  const testing::CubeRig rig;
  const ElasticBody& body = rig.body;
  ComplianceColumns columns(body.free_factor, body.dofs, rig.columns->row_nodes());
  CompliancePrefetch prefetch(body, columns.row_nodes());
  const Eigen::Vector3d tool(0.01, -0.02, 0.004);  // 4 mm above the front face
  const std::set<int> expected =
      nodes_of_groups_near(body, columns, tool, CompliancePrefetch::kToolReach);
  ASSERT_GT(expected.size(), 8u);
  ASSERT_LT(expected.size(), columns.row_nodes().size() / 4);

  prefetch.request_near(tool, columns);
  deliver_until(prefetch, columns, expected.size());
  std::set<int> delivered;
  for (const auto& [node, column] : columns.columns()) delivered.insert(node);
  EXPECT_EQ(delivered, expected);

  // The same columns solved here, on this thread, as the simulation solves a node it needs.
  ComplianceColumns here(body.free_factor, body.dofs, columns.row_nodes());
  for (int node : expected) {
    const ComplianceColumn& mine = here.column(node);
    const ComplianceColumn& prefetched = columns.columns().at(node);
    ASSERT_EQ(mine.rows(), prefetched.rows());
    EXPECT_TRUE((mine.array() == prefetched.array()).all()) << "node " << node;
  }
}

TEST(CompliancePrefetch, NeverReplacesAColumnTheCallerHasAndSkipsWhatItHas) {
  const testing::CubeRig rig;
  const ElasticBody& body = rig.body;
  ComplianceColumns columns(body.free_factor, body.dofs, rig.columns->row_nodes());
  CompliancePrefetch prefetch(body, columns.row_nodes());
  const int first = columns.row_nodes()[0];
  const ComplianceColumn* held =
      &columns.column(first);  // the caller solved the first group itself
  const std::size_t group = columns.column_count();
  // Asked for explicitly (request() does not know the caller has it): solved again, not moved in.
  std::vector<NodeDistance> asked;
  for (int node : columns.row_nodes()) asked.push_back({node, 0.0});
  asked.resize(2 * static_cast<std::size_t>(ComplianceColumns::kGroupSize));
  prefetch.request(asked);
  deliver_until(prefetch, columns, 2 * group);
  EXPECT_EQ(columns.column_count(), 2 * group);
  EXPECT_EQ(&columns.column(first), held) << "a column the caller held was replaced";
  // Far from every row node: nothing is asked for, nothing comes.
  prefetch.request_near(Eigen::Vector3d(10, 10, 10), columns);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(prefetch.deliver(columns), 0u);
}

}  // namespace
}  // namespace cohaptic
