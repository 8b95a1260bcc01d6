// Benchmarks of FEM against FEM (common/sim/fem_pair_coupling.h) on the paired boxes
// (tests/support/fem_pair_rig.h: A 96 nodes, B 210), A pushed 5 mm into B (15 of 24 back
// nodes pushing), A's and B's compliance columns cached as a server holds them:
//   BM_FemPairContact                 the server's coupled contact solve of a step
//                                     (both normal compliances, the held tool, the LCP)
//   BM_FemPairSupportChange/folded    a change of the pushing set S, then M~ of the tool's
//                                     node and its front-face neighbours: B folded into A's
//                                     compliance by Woodbury (SupportedCompliance) on columns
//                                     A holds
//   BM_FemPairSupportChange/refactor  the same the naive way: K_A plus the support springs
//                                     assembled, factored by CHOLMOD, the columns solved
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "common/condense/naive_condensation.h"
#include "common/fem/sparse_cholesky.h"
#include "common/sim/supported_compliance.h"
#include "support/fem_pair_rig.h"

namespace cohaptic {
namespace {

// The pushing set of a 5 mm push, its normals and B's compliance there, and M~'s nodes.
struct FemPairBench {
  testing::CoupledPush push{0.0, 5e-3};
  std::vector<int> support_nodes;
  Eigen::Matrix3Xd normals;
  Eigen::MatrixXd support;
  std::vector<int> contact;
  FemPairBench() {
    std::vector<Eigen::Index> set;
    for (Eigen::Index j = 0; j < push.contact.pushes.size(); ++j)
      if (push.contact.pushes[j] > 0) set.push_back(j);
    const auto s = static_cast<Eigen::Index>(set.size());
    normals.resize(3, s);
    support.resize(s, s);
    for (Eigen::Index a = 0; a < s; ++a) {
      const PolygonCollision& collision = push.collisions[static_cast<std::size_t>(set[static_cast<std::size_t>(a)])];
      support_nodes.push_back(collision.active);
      normals.col(a) = collision.normal;
      for (Eigen::Index b = 0; b < s; ++b)
        support(a, b) = push.contact.behind_compliance(set[static_cast<std::size_t>(a)], set[static_cast<std::size_t>(b)]);
    }
    const ElasticBody& a = push.rig.front;
    const int tool = push.free.tool_dofs[0] / 3;
    contact.push_back(tool);
    for (int node : a.surface.nodes)
      if (node != tool && std::abs(a.mesh.nodes(0, node) - a.mesh.nodes(0, tool)) < 1e-9 &&
          (a.mesh.nodes.col(node) - a.mesh.nodes.col(tool)).norm() < 0.03)
        contact.push_back(node);
    // Cache every column M~ and the support read, as the server's columns would hold them.
    std::vector<int> nodes = contact;
    nodes.insert(nodes.end(), support_nodes.begin(), support_nodes.end());
    push.front_columns->compute_columns(nodes);
  }
};

void BM_FemPairContact(benchmark::State& state) {
  FemPairBench bench;
  testing::CoupledPush& push = bench.push;
  for (auto _ : state) {
    const FemPairContact contact =
        solve_fem_pair_contact(push.collisions, *push.front_columns, push.free.tool_dofs, *push.rig.behind_columns);
    benchmark::DoNotOptimize(contact.pushes.data());
  }
  state.counters["candidates"] = static_cast<double>(push.collisions.size());
  state.counters["pushing"] = static_cast<double>((push.contact.pushes.array() > 0).count());
}

void BM_FemPairSupportChange_folded(benchmark::State& state) {
  FemPairBench bench;
  const ElasticBody& a = bench.push.rig.front;
  for (auto _ : state) {
    SupportedCompliance supported(*bench.push.front_columns, a.dofs, bench.support_nodes, bench.normals, bench.support);
    const CondensedOperator m = naive_condensation(supported, a.dofs, bench.contact, {});
    benchmark::DoNotOptimize(m.m_cc.data());
  }
  state.counters["support_nodes"] = static_cast<double>(bench.support_nodes.size());
  state.counters["contact_nodes"] = static_cast<double>(bench.contact.size());
}

void BM_FemPairSupportChange_refactor(benchmark::State& state) {
  FemPairBench bench;
  const ElasticBody& a = bench.push.rig.front;
  for (auto _ : state) {
    const SparseCholesky factor(testing::stiffness_with_support(a, bench.support_nodes, bench.normals, bench.support));
    ComplianceColumns columns(factor, a.dofs, a.surface.nodes);
    const CondensedOperator m = naive_condensation(columns, a.dofs, bench.contact, {});
    benchmark::DoNotOptimize(m.m_cc.data());
  }
  state.counters["support_nodes"] = static_cast<double>(bench.support_nodes.size());
  state.counters["contact_nodes"] = static_cast<double>(bench.contact.size());
}

BENCHMARK(BM_FemPairContact)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FemPairSupportChange_folded)->Name("BM_FemPairSupportChange/folded")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FemPairSupportChange_refactor)->Name("BM_FemPairSupportChange/refactor")->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace cohaptic
