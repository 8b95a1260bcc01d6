// Benchmarks of the interaction between two bodies, beside the several-objects paper's
// Tables 1 and 3 (Pentium IV 1.7 GHz), on its behind object B: a box of 86.5 x 130.8 x
// 108.7 mm, 9 x 14 x 12 cells (1,950 nodes; the paper's 1,906), E = 1.0 MPa, nu = 0.216,
// bottom and far face fixed, its compliance columns for the near face computed up front
// (the paper's pre-computable matrix).
//   BM_BehindReaction/<n>     f_c = L_cc^-1 u_c for n displaced nodes (Table 3's reaction
//                             force: 0.076 / 0.089 / 0.110 / 0.163 ms for n = 1..4)
//   BM_BehindDeformation/<n>  u_o = L_oc f_c for every surface node (Table 3's deformation:
//                             0.157 / 0.200 / 0.480 / 1.909 ms)
//   BM_BehindFullSolve/<n>    the naive answer to both: a CHOLMOD factorisation and solve
//                             of B with the n nodes prescribed
//   BM_InteractionStep/<workflow>/<pairs>  one step (update of pairs, collision tests,
//                             forcible displacement, deformation, conveyance, addition of
//                             pairs) with 1..16 colliding pairs, naive (a deformation per
//                             pair) and improved (one per step) workflow (Sec. 2.2); counters:
//                             the collisions kept (a pulling one is released) and the
//                             displaced nodes
//   BM_UpdatePairs/<pairs>, BM_InstantCollision, BM_DetailedCollision,
//   BM_ForcibleDisplacement/<pairs>, BM_Conveyance/<pairs>, BM_AddPairs: Table 1's rows
//                             (update of pairs 0.0120 ms, instant collision detection
//                             0.0047 / 0.0090 ms, collision procedures 0.0247 / 0.0360 ms,
//                             conveyance of reaction 0.0105 ms, addition of pairs 0.0026 ms)
// BLAS runs on one thread, as in the server.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>

#include "common/fem/static_solve.h"
#include "common/interaction/interaction_step.h"
#include "common/util/blas_threads.h"
#include "support/paired_boxes.h"

namespace cohaptic {
namespace {

struct InteractionFixture {
  std::unique_ptr<testing::PairedBoxesRig> rig;
  std::vector<int> face;  // B's near-face nodes nearest its centre, nearest first
};

InteractionFixture& interaction_fixture() {
  static InteractionFixture f = [] {
    use_single_blas_thread();
    InteractionFixture made;
    testing::PairedBoxesOptions options;
    options.behind_divisions = {9, 14, 12};
    options.front_divisions = {4, 7, 4};
    made.rig = std::make_unique<testing::PairedBoxesRig>(options);
    const ElasticBody& behind = made.rig->behind;
    const Eigen::Vector3d centre(0, 0.0654, 0.0544);
    for (int node : behind.surface.nodes)
      if (behind.mesh.nodes(0, node) < 1e-9) made.face.push_back(node);
    std::sort(made.face.begin(), made.face.end(), [&](int a, int b) {
      return (behind.mesh.nodes.col(a) - centre).norm() <
             (behind.mesh.nodes.col(b) - centre).norm();
    });
    made.rig->behind_columns->compute_columns(made.face);
    return made;
  }();
  return f;
}

// The first n face nodes, ascending, each pushed 1 mm into B.
struct Displaced {
  std::vector<int> nodes;
  Eigen::VectorXd displacement;
  explicit Displaced(std::size_t n)
      : nodes(interaction_fixture().face.begin(),
              interaction_fixture().face.begin() + static_cast<std::ptrdiff_t>(n)) {
    std::sort(nodes.begin(), nodes.end());
    displacement = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(n));
    for (std::size_t j = 0; j < n; ++j) displacement[3 * static_cast<Eigen::Index>(j)] = 0.001;
  }
};

void BM_BehindReaction(benchmark::State& state) {
  InteractionFixture& f = interaction_fixture();
  const Displaced displaced(static_cast<std::size_t>(state.range(0)));
  Eigen::VectorXd forces(displaced.displacement.size());
  CondensedResponseWorkspace workspace;
  for (auto _ : state) {
    condensed_reaction(*f.rig->behind_columns, f.rig->behind.dofs, displaced.nodes,
                       displaced.displacement, forces, workspace);
    benchmark::DoNotOptimize(forces.data());
  }
}
BENCHMARK(BM_BehindReaction)->DenseRange(1, 4)->Unit(benchmark::kMicrosecond);

void BM_BehindDeformation(benchmark::State& state) {
  InteractionFixture& f = interaction_fixture();
  const Displaced displaced(static_cast<std::size_t>(state.range(0)));
  Eigen::VectorXd forces(displaced.displacement.size());
  CondensedResponseWorkspace workspace;
  condensed_reaction(*f.rig->behind_columns, f.rig->behind.dofs, displaced.nodes,
                     displaced.displacement, forces, workspace);
  Eigen::VectorXd deformation(3 *
                              static_cast<Eigen::Index>(f.rig->behind_columns->row_nodes().size()));
  for (auto _ : state) {
    condensed_deformation(*f.rig->behind_columns, displaced.nodes, forces, deformation);
    benchmark::DoNotOptimize(deformation.data());
  }
  state.counters["surface_nodes"] = static_cast<double>(f.rig->behind_columns->row_nodes().size());
}
BENCHMARK(BM_BehindDeformation)->DenseRange(1, 4)->Unit(benchmark::kMicrosecond);

void BM_BehindFullSolve(benchmark::State& state) {
  InteractionFixture& f = interaction_fixture();
  const Displaced displaced(static_cast<std::size_t>(state.range(0)));
  std::vector<int> dofs;
  for (int node : displaced.nodes)
    for (int axis = 0; axis < 3; ++axis) dofs.push_back(3 * node + axis);
  Eigen::VectorXd values = displaced.displacement;
  for (auto _ : state) {
    const ConstrainedStaticSolver solver(f.rig->behind.stiffness, f.rig->behind.dofs, dofs);
    benchmark::DoNotOptimize(solver.solve(values).reaction.data());
  }
  state.counters["nodes"] = f.rig->behind.mesh.node_count();
}
BENCHMARK(BM_BehindFullSolve)->DenseRange(1, 4)->Unit(benchmark::kMillisecond);

// `pairs` active nodes 1 mm inside B, each in front of its own face node (from the
// centre out), paired with it; an active body without triangles, so no pair is added.
struct PairsScenario {
  Eigen::Matrix3Xd active;
  SurfaceAdjacency active_surface;
  NodePairList list;
  explicit PairsScenario(int pairs)
      : active(3, pairs), active_surface(make_surface_adjacency({}, pairs)) {
    const InteractionFixture& f = interaction_fixture();
    list.paired.assign(static_cast<std::size_t>(pairs), 1);
    for (int k = 0; k < pairs; ++k) {
      const int node = f.face[static_cast<std::size_t>(k)];
      // Off the node, inside one of its triangles: a foot strictly inside.
      active.col(k) = f.rig->behind.mesh.nodes.col(node) + Eigen::Vector3d(0.001, 0.0021, 0.0013);
      list.pairs.push_back({k, node});
    }
  }
  InteractingBodies bodies() {
    InteractionFixture& f = interaction_fixture();
    return {active,
            active_surface,
            f.rig->behind.mesh.nodes,
            f.rig->behind_surface,
            f.rig->behind.dofs,
            *f.rig->behind_columns};
  }
};

void BM_InteractionStep(benchmark::State& state) {
  const auto workflow =
      state.range(0) == 0 ? InteractionWorkflow::naive : InteractionWorkflow::improved;
  PairsScenario scenario(static_cast<int>(state.range(1)));
  CondensedResponseWorkspace workspace;
  std::size_t collisions = 0, displaced = 0;
  for (auto _ : state) {
    const InteractionStep step =
        interaction_step(scenario.list, scenario.bodies(), workflow, workspace);
    collisions = step.collisions.size();
    displaced = step.displacement.nodes.size();
    benchmark::DoNotOptimize(step.active_forces.data());
  }
  state.counters["collisions"] = static_cast<double>(collisions);
  state.counters["displaced_nodes"] = static_cast<double>(displaced);
}
BENCHMARK(BM_InteractionStep)
    ->ArgNames({"improved", "pairs"})
    ->ArgsProduct({{0, 1}, {1, 2, 4, 8, 16}})
    ->Unit(benchmark::kMicrosecond);

void BM_UpdatePairs(benchmark::State& state) {
  PairsScenario scenario(static_cast<int>(state.range(0)));
  const InteractingBodies bodies = scenario.bodies();
  for (auto _ : state)
    benchmark::DoNotOptimize(update_node_pairs(scenario.list, bodies.active_positions,
                                               bodies.passive_positions, bodies.passive_surface));
}
BENCHMARK(BM_UpdatePairs)->Arg(1)->Arg(16)->Unit(benchmark::kMicrosecond);

void BM_InstantCollision(benchmark::State& state) {
  PairsScenario scenario(1);
  const InteractingBodies bodies = scenario.bodies();
  const Eigen::Vector3d active = scenario.active.col(0);
  const int passive = scenario.list.pairs[0].passive;
  for (auto _ : state)
    benchmark::DoNotOptimize(
        instant_collision_test(active, passive, bodies.passive_positions, bodies.passive_surface));
}
BENCHMARK(BM_InstantCollision)->Unit(benchmark::kMicrosecond);

void BM_DetailedCollision(benchmark::State& state) {
  PairsScenario scenario(1);
  const InteractingBodies bodies = scenario.bodies();
  const Eigen::Vector3d active = scenario.active.col(0);
  const int passive = scenario.list.pairs[0].passive;
  for (auto _ : state)
    benchmark::DoNotOptimize(
        detailed_collision_test(active, passive, bodies.passive_positions, bodies.passive_surface));
}
BENCHMARK(BM_DetailedCollision)->Unit(benchmark::kMicrosecond);

void BM_ForcibleDisplacement(benchmark::State& state) {
  PairsScenario scenario(static_cast<int>(state.range(0)));
  const InteractingBodies bodies = scenario.bodies();
  const std::vector<PolygonCollision> collisions = find_polygon_collisions(scenario.list, bodies);
  for (auto _ : state)
    benchmark::DoNotOptimize(
        forcible_displacement(collisions, bodies.passive_dofs.fixed_axes).displacement.data());
}
BENCHMARK(BM_ForcibleDisplacement)->Arg(1)->Arg(16)->Unit(benchmark::kMicrosecond);

void BM_Conveyance(benchmark::State& state) {
  PairsScenario scenario(static_cast<int>(state.range(0)));
  CondensedResponseWorkspace workspace;
  const InteractionStep step =
      interaction_step(scenario.list, scenario.bodies(), InteractionWorkflow::improved, workspace);
  for (auto _ : state)
    benchmark::DoNotOptimize(convey_reaction(step.displacement, step.passive_forces).data());
}
BENCHMARK(BM_Conveyance)->Arg(1)->Arg(16)->Unit(benchmark::kMicrosecond);

// Addition of pairs around one colliding node of A's face (the paper's front box): its
// neighbours join, then the list is cut back for the next iteration.
void BM_AddPairs(benchmark::State& state) {
  InteractionFixture& f = interaction_fixture();
  const testing::PairedBoxesRig& rig = *f.rig;
  const int centre = rig.front_face[rig.front_face.size() / 2];
  NodePairList list = make_node_pairs(std::span(&centre, 1), rig.front.mesh.nodes,
                                      rig.behind.surface.nodes, rig.behind.mesh.nodes);
  const std::vector<int> colliding{0};
  int added = 0;
  for (auto _ : state) {
    added = add_neighbour_pairs(list, colliding, rig.front.mesh.nodes, rig.front_surface,
                                rig.behind.mesh.nodes, rig.behind_surface);
    for (std::size_t k = 1; k < list.pairs.size(); ++k)
      list.paired[static_cast<std::size_t>(list.pairs[k].active)] = 0;
    list.pairs.resize(1);
  }
  state.counters["added"] = added;
}
BENCHMARK(BM_AddPairs)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace cohaptic
