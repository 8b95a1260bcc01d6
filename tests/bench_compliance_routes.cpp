// The compliance of every row node of the brain, two routes in the same run:
//   BM_BrainRowCompliance/route:0/mesh:<mesh>  ComplianceColumns: one supernodal solve per group of
//                                        4 row nodes (12 right-hand sides), on this thread;
//   BM_BrainRowCompliance/route:1/mesh:<mesh>  schur_compliance.h: one factorisation with the row
//                                        dofs last, and the inverse of its trailing block
//                                        (BLAS on kFactorBlasThreads threads).
// <mesh>: the mesh of scenes/brain.yaml replaced by kMeshes[mesh] (scenes/brain/).
// Rows: the whole surface, as the server keeps them for a scene with an obstacle (the skull).
// Counters: row nodes, row nodes per second of wall time, the result's bytes, and the peak
// resident memory of the run (the kernel's high-water mark, reset before it).
#include <benchmark/benchmark.h>

#include <fstream>
#include <map>
#include <memory>

#include "common/fem/schur_compliance.h"
#include "common/model/compliance_setup.h"
#include "common/model/model.h"
#include "common/util/blas_threads.h"
#include "support/brain_scene.h"

namespace cohaptic {
namespace {

const char* const kMeshes[] = {"brain.msh", "brain_fine.msh", "brain_graded.msh"};

const Model& brain_model(int mesh) {
  static std::map<int, std::unique_ptr<Model>> models;
  auto& slot = models[mesh];
  if (!slot) {
    slot = std::make_unique<Model>(build_model(testing::brain_scene(kMeshes[mesh])));
  }
  return *slot;
}

// The kernel's resident high-water mark, reset (Linux: /proc/self/clear_refs "5"), and read
// [bytes].
void reset_peak_memory() { std::ofstream("/proc/self/clear_refs") << "5"; }
double peak_memory_bytes() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmHWM:", 0) == 0) return 1024.0 * std::stod(line.substr(6));
  return 0;
}

void BM_BrainRowCompliance(benchmark::State& state) {
  const int route = static_cast<int>(state.range(0));
  const Model& model = brain_model(static_cast<int>(state.range(1)));
  const ElasticBody& brain = single_elastic_body(model);
  const std::vector<int> rows = compliance_row_nodes(brain, true);
  const SparseMatrix k_ff = restrict_to_dofs(brain.stiffness, brain.dofs.free_dofs);
  reset_peak_memory();
  for (auto _ : state) {
    ComplianceColumns columns(brain.free_factor, brain.dofs, rows);
    if (route > 0)
      compute_row_columns_by_schur(columns, k_ff, brain.dofs);
    else
      columns.compute_columns(rows);
    benchmark::DoNotOptimize(columns.column_count());
  }
  const auto m = static_cast<double>(3 * rows.size());
  state.SetLabel(kMeshes[state.range(1)]);
  state.counters["nodes"] = brain.mesh.node_count();
  state.counters["row_nodes"] = static_cast<double>(rows.size());
  state.counters["row_nodes_per_s"] = benchmark::Counter(
      static_cast<double>(rows.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["columns_MB"] = 8 * m * m / 1e6;
  state.counters["peak_MB"] = peak_memory_bytes() / 1e6;
}

// The BLAS kernels every route ran on, in the run's context (the JSON's "blas_kernels").
const bool kKernelsInContext = (benchmark::AddCustomContext("blas_kernels", blas_kernels()), true);

BENCHMARK(BM_BrainRowCompliance)
    ->ArgNames({"route", "mesh"})
    ->ArgsProduct({{0, 1}, {0, 1, 2}})
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kSecond);

}  // namespace
}  // namespace cohaptic
