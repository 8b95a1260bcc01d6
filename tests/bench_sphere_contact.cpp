// The client's haptic tick under the sphere contact model beside the paper's translation
// model, from IRs the simulation built at the same tool position and held set B:
//   BM_Tick/<model>/<|B|>   one evaluate_force call as the tool creeps deeper and sideways
//                            (counters: contact_nodes, the IR's contact (row) nodes, which
//                            are the sphere's candidates; held, the nodes the sphere holds
//                            at its first position; boundary_nodes, |B|)
//   BM_TickColdStart/sphere/<|B|>  the same with the sphere solve's warm start cleared before
//                            every tick (the naive way: each tick's active set searched from
//                            nothing)
//   BM_PrepareIr/<model>/<|B|>  what a client does once per IR received
// The cube has 16 divisions (8.1 mm cells); a 24 mm sphere pressed 6 mm into its top
// holds about 20 nodes, and the IR's candidates (the sphere's patch with one ring) are
// about 50. B is the step-delay set of |B| surface nodes nearest the contact. BLAS runs on
// one thread, as in the server.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include "common/ir/evaluate_force.h"
#include "common/scene/load_scene.h"
#include "common/sim/simulation.h"
#include "common/util/blas_threads.h"
#include "support/cube_scene.h"

namespace cohaptic {
namespace {

const Eigen::Vector3d kTool(0.003, -0.002, 0.018);  // 24 mm sphere 6 mm deep [m]

testing::CubeRig& rig() {
  static testing::CubeRig cube([] {
    testing::CubeSceneOptions options;
    options.divisions = 16;
    options.tools = "[{name: A, shape: sphere, radius: 24}]";
    options.force_limit = 1000;  // the scene's largest; the IRs below are unlimited
    return options;
  }());
  return cube;
}

// The user's IR under `model` with |B| = boundary_nodes, built once per setting.
const PreparedIR& prepared_ir(ContactModel model, int boundary_nodes) {
  static std::map<std::pair<ContactModel, int>, std::shared_ptr<const PreparedIR>> built;
  auto& ir = built[{model, boundary_nodes}];
  if (!ir) {
    SimulationOptions options;
    options.ir.contact_model = model;
    options.ir.patch_rings = 1;
    options.ir.force_limit = 1e9;
    options.step_delay_nodes = boundary_nodes;
    Simulation simulation(rig().body, rig().model->obstacles, *rig().columns, rig().model->scene.tools, options);
    simulation.set_tool(0, kTool);
    simulation.step(0);
    ir = simulation.ir(0);
  }
  return *ir;
}

ContactModel model_of(const benchmark::State& state) {
  return state.range(0) == 0 ? ContactModel::node_translation : ContactModel::sphere;
}

void run_ticks(benchmark::State& state, bool cold_start) {
  const PreparedIR& prepared = prepared_ir(model_of(state), static_cast<int>(state.range(1)));
  const CondensedFemIr& fem = condensed_fem(prepared.ir);
  EvaluationState warm = make_evaluation_state(prepared);
  std::size_t tick = 0;
  for (auto _ : state) {
    // 0.1 mm deeper and 0.2 mm sideways over 1000 ticks: the active set changes now and then.
    const double phase = static_cast<double>(tick++ % 1000) * 1e-3;
    const Eigen::Vector3d tool = kTool + Eigen::Vector3d(2e-4 * phase, 0, -1e-4 * phase);
    EvaluationState cold;  // no warm start: each tick solves from the empty set
    const ForceSample sample = evaluate_force(prepared, cold_start ? cold : warm, tool, {}, 1e-3);
    benchmark::DoNotOptimize(sample.force.data());
  }
  int held = 0;
  for (int i = 0; i < fem.row_node_count; ++i)
    held += (fem.rest_positions.col(i) - kTool).norm() < prepared.ir.tool_radius;
  state.counters["contact_nodes"] = fem.row_node_count;
  if (fem.contact_model == ContactModel::sphere) state.counters["held"] = held;
  state.counters["boundary_nodes"] = static_cast<double>(fem.node_count() - fem.row_node_count);
}

void BM_Tick(benchmark::State& state) { run_ticks(state, false); }
void BM_TickColdStart(benchmark::State& state) { run_ticks(state, true); }

void BM_PrepareSphereIr(benchmark::State& state) {
  const PreparedIR& prepared = prepared_ir(model_of(state), static_cast<int>(state.range(1)));
  for (auto _ : state) {
    const PreparedIR again = prepare_ir(prepared.ir);
    benchmark::DoNotOptimize(again.condition_estimate);
  }
}

void register_sphere_contact_benchmarks() {
  use_single_blas_thread();
  for (const auto& [name, model] : {std::pair{"translation", 0}, std::pair{"sphere", 1}}) {
    const std::string suffix = std::string("/") + name;
    benchmark::RegisterBenchmark(("BM_Tick" + suffix).c_str(), BM_Tick)->Args({model, 0})->Args({model, 300})->Unit(benchmark::kMicrosecond);
    if (model == 1)
      benchmark::RegisterBenchmark(("BM_TickColdStart" + suffix).c_str(), BM_TickColdStart)
          ->Args({model, 0})
          ->Args({model, 300})
          ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_PrepareIr" + suffix).c_str(), BM_PrepareSphereIr)
        ->Args({model, 0})
        ->Args({model, 300})
        ->Unit(benchmark::kMicrosecond);
  }
}

const int sphere_contact_benchmarks_registered = (register_sphere_contact_benchmarks(), 0);

}  // namespace
}  // namespace cohaptic
