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

#include <vector>

#include "common/condense/naive_condensation.h"
#include "common/fem/sparse_cholesky.h"
#include "common/sim/supported_compliance.h"
#include "support/fem_pair_rig.h"

namespace cohaptic {
namespace {

// A 5 mm push, its pushing set and M~'s nodes, with every column M~ and the support read
// cached, as the server's columns would hold them.
struct FemPairBench {
  testing::CoupledPush push{0.0, 5e-3};
  testing::PushingSupport support = testing::pushing_support(push);
  std::vector<int> contact = testing::tool_neighbourhood(push);
  FemPairBench() {
    std::vector<int> nodes = contact;
    nodes.insert(nodes.end(), support.nodes.begin(), support.nodes.end());
    push.front_columns->compute_columns(nodes);
  }
};

void BM_FemPairContact(benchmark::State& state) {
  FemPairBench bench;
  testing::CoupledPush& push = bench.push;
  for (auto _ : state) {
    const FemPairContact contact = solve_fem_pair_contact(
        push.collisions, *push.front_columns, push.free.tool_dofs, *push.rig.behind_columns);
    benchmark::DoNotOptimize(contact.pushes.data());
  }
  state.counters["candidates"] = static_cast<double>(push.collisions.size());
  state.counters["pushing"] = static_cast<double>((push.contact.pushes.array() > 0).count());
}

void BM_FemPairSupportChange_folded(benchmark::State& state) {
  FemPairBench bench;
  const ElasticBody& a = bench.push.rig.front;
  for (auto _ : state) {
    SupportedCompliance supported(*bench.push.front_columns, a.dofs, bench.support.nodes,
                                  bench.support.normals, bench.support.compliance);
    const CondensedOperator m = naive_condensation(supported, a.dofs, bench.contact, {});
    benchmark::DoNotOptimize(m.m_cc.data());
  }
  state.counters["support_nodes"] = static_cast<double>(bench.support.nodes.size());
  state.counters["contact_nodes"] = static_cast<double>(bench.contact.size());
}

void BM_FemPairSupportChange_refactor(benchmark::State& state) {
  FemPairBench bench;
  const ElasticBody& a = bench.push.rig.front;
  for (auto _ : state) {
    const SparseCholesky factor(testing::stiffness_with_support(
        a, bench.support.nodes, bench.support.normals, bench.support.compliance));
    ComplianceColumns columns(factor, a.dofs, a.surface.nodes);
    const CondensedOperator m = naive_condensation(columns, a.dofs, bench.contact, {});
    benchmark::DoNotOptimize(m.m_cc.data());
  }
  state.counters["support_nodes"] = static_cast<double>(bench.support.nodes.size());
  state.counters["contact_nodes"] = static_cast<double>(bench.contact.size());
}

BENCHMARK(BM_FemPairContact)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FemPairSupportChange_folded)
    ->Name("BM_FemPairSupportChange/folded")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FemPairSupportChange_refactor)
    ->Name("BM_FemPairSupportChange/refactor")
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace cohaptic
