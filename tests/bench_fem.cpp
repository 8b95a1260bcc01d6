// Benchmarks of the foundation: stiffness assembly, CHOLMOD factorisation of K_ff,
// compliance columns per node, and the whole touchable block (batched multi-RHS solve
// against the naive one-solve-per-node). The argument is the cube's divisions per edge:
// 11 is the paper's cube (1,728 nodes), 22 a finer one (12,167 nodes).
//   BM_ComplianceGroupSolve/<nodes>  one solve for the columns of that many neighbouring
//                                    surface nodes of the brain (8,991 free dofs): the
//                                    cost of a compliance solve group of that size
#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include "common/fem/compliance.h"
#include "common/model/compliance_setup.h"
#include "common/model/model.h"
#include "common/scene/load_scene.h"

namespace cohaptic {
namespace {

const Model& cube_model(int divisions) {
  static std::map<int, std::unique_ptr<Model>> models;
  auto& slot = models[divisions];
  if (!slot) {
    const std::string yaml = fmt::format(R"(
units: mm
objects:
  - name: cube
    mesh: {{box: {{min: [-65, -65, -130], size: [130, 130, 130], divisions: [{0}, {0}, {0}]}}}}
    material: {{youngs_modulus: 1.0e6, poisson_ratio: 0.4}}
    fixed: [{{plane: {{point: [0, 0, -130], normal: [0, 0, 1]}}}}]
    touchable: [{{plane: {{point: [0, 0, 0], normal: [0, 0, 1]}}}}]
tools: [{{name: A}}]
)",
                                         divisions);
    slot = std::make_unique<Model>(build_model(parse_scene(yaml, "bench-cube.yaml")));
  }
  return *slot;
}

void set_mesh_counters(benchmark::State& state, const Model& model) {
  const ElasticBody& body = single_elastic_body(model);
  state.counters["nodes"] = body.mesh.node_count();
  state.counters["tets"] = body.mesh.tet_count();
}

void BM_Assemble(benchmark::State& state) {
  const Model& model = cube_model(static_cast<int>(state.range(0)));
  const ElasticBody& body = single_elastic_body(model);
  for (auto _ : state) benchmark::DoNotOptimize(assemble_stiffness(body.mesh, body.spec.material));
  set_mesh_counters(state, model);
}

void BM_Factor(benchmark::State& state) {
  const Model& model = cube_model(static_cast<int>(state.range(0)));
  const ElasticBody& body = single_elastic_body(model);
  const SparseMatrix k_ff = restrict_to_dofs(body.stiffness, body.dofs.free_dofs);
  double nonzeros = 0;
  for (auto _ : state) {
    SparseCholesky factor(k_ff);
    nonzeros = factor.factor_nonzeros();
  }
  set_mesh_counters(state, model);
  state.counters["free_dofs"] = body.dofs.free_count();
  state.counters["factor_nnz"] = nonzeros;
}

void BM_ComplianceColumn(benchmark::State& state) {
  const Model& model = cube_model(static_cast<int>(state.range(0)));
  const ElasticBody& body = single_elastic_body(model);
  const int node = body.touchable_nodes[body.touchable_nodes.size() / 2];
  for (auto _ : state) {
    ComplianceColumns columns(body.free_factor, body.dofs, body.touchable_nodes);
    benchmark::DoNotOptimize(columns.column(node).data());
  }
  set_mesh_counters(state, model);
}

// The whole touchable block: one solve with 3|T| right-hand sides ...
void BM_ComplianceSurfaceBlock_batched(benchmark::State& state) {
  const Model& model = cube_model(static_cast<int>(state.range(0)));
  const ElasticBody& body = single_elastic_body(model);
  for (auto _ : state) {
    ComplianceColumns columns(body.free_factor, body.dofs, body.touchable_nodes);
    columns.compute_columns(body.touchable_nodes);
    benchmark::DoNotOptimize(columns.column_count());
  }
  set_mesh_counters(state, model);
  state.counters["touchable_nodes"] = static_cast<double>(body.touchable_nodes.size());
}

// ... against the naive way, one 3-column solve per node.
void BM_ComplianceSurfaceBlock_per_node(benchmark::State& state) {
  const Model& model = cube_model(static_cast<int>(state.range(0)));
  const ElasticBody& body = single_elastic_body(model);
  for (auto _ : state) {
    ComplianceColumns columns(body.free_factor, body.dofs, body.touchable_nodes);
    for (int node : body.touchable_nodes) columns.column(node);
    benchmark::DoNotOptimize(columns.column_count());
  }
  set_mesh_counters(state, model);
  state.counters["touchable_nodes"] = static_cast<double>(body.touchable_nodes.size());
}

// A solve group's cost against its size: what ComplianceColumns::kGroupSize trades.
void BM_ComplianceGroupSolve(benchmark::State& state) {
  static const Model model =
      build_model(load_scene(std::string(COHAPTIC_SOURCE_DIR) + "/scenes/brain.yaml"));
  const ElasticBody& brain = single_elastic_body(model);
  const std::vector<int> rows = compliance_row_nodes(brain, true);
  const std::vector<int> group(rows.begin(), rows.begin() + state.range(0));
  for (auto _ : state) {
    ComplianceColumns columns(brain.free_factor, brain.dofs, group);
    columns.compute_columns(group);  // one solve: the group is the whole row set
    benchmark::DoNotOptimize(columns.column_count());
  }
  state.counters["cpu_s_per_node"] = benchmark::Counter(
      static_cast<double>(state.range(0)),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

BENCHMARK(BM_Assemble)->Arg(11)->Arg(22)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Factor)->Arg(11)->Arg(22)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ComplianceColumn)->Arg(11)->Arg(22)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ComplianceSurfaceBlock_batched)->Arg(11)->Arg(22)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ComplianceSurfaceBlock_per_node)->Arg(11)->Arg(22)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ComplianceGroupSolve)->Arg(1)->Arg(4)->Arg(16)->Arg(64)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cohaptic
