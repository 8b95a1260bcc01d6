// Benchmarks of the separation body: the haptic tick against the
// number of patch nodes — elastic, tearing, sliding and laser ticks, and a pushing tool
// hovering out of reach (its search for the nearest interface point) — beside the
// naive way (a live sparse FEM solve of the two layers per tick), and the precomputation
// per field. The argument is the divisions of the 40 mm square interface: 10, 20 and 30
// give 121, 441 and 961 patch nodes.
#include <benchmark/benchmark.h>

#include <chrono>
#include <map>
#include <memory>

#include "common/separation/laser_groove.h"
#include "common/separation/pull_loop.h"
#include "common/separation/separation_tool.h"
#include "common/separation/tied_system.h"
#include "common/separation/separation_setup.h"

namespace cohaptic {
namespace {

TwoLayerBoxes boxes(int divisions) {
  TwoLayerBoxes b;
  b.divisions = {divisions, divisions};
  return b;
}

const SeparationSetup& layers(int divisions) {
  static std::map<int, std::unique_ptr<SeparationSetup>> setups;
  auto& slot = setups[divisions];
  if (!slot)
    slot = std::make_unique<SeparationSetup>(
        make_two_layer_setup(boxes(divisions), FieldSettings{}, SeparationSettings{}));
  return *slot;
}

void set_counters(benchmark::State& state, const SeparationPatch& patch) {
  state.counters["patch_nodes"] = patch.node_count();
  state.counters["patch_triangles"] = patch.triangle_count();
}

// A grasp at the middle of the interface moving in small circles: no crack in reach, so
// every tick is the interpolated force of Eq. 2 alone.
void BM_SeparationTick_elastic(benchmark::State& state) {
  const SeparationPatch& patch = layers(static_cast<int>(state.range(0))).patch;
  SeparationState separation = make_separation_state(patch);
  const int node = nearest_patch_node(patch, Eigen::Vector3d(0.0203, 0.0197, 0));
  const Eigen::Vector3d start = patch.positions.col(node);
  SeparationContact contact =
      begin_contact(patch, ContactMode::grasp, contact_at_node(patch, node), start);
  int i = 0;
  for (auto _ : state) {
    const double t = 1e-3 * (i++ % 6283);
    const Eigen::Vector3d tool = start + 1e-3 * Eigen::Vector3d(std::cos(t), std::sin(t), 0.5);
    benchmark::DoNotOptimize(step_contact(patch, separation, contact, tool).force);
  }
  set_counters(state, patch);
}

// The ticks of the Fig. 10 pull between B and C: each one solves the area split that holds
// the force at J_c l_n. Only the ticks are timed; the state is reset between pulls.
void BM_SeparationTick_tearing(benchmark::State& state) {
  const SeparationPatch& patch = layers(static_cast<int>(state.range(0))).patch;
  const int node = nearest_patch_node(patch, Eigen::Vector3d(0, 0.02, 0));
  PullLoopSettings settings;
  settings.node = node;
  const PullLoop loop = run_pull_loop(patch, make_separation_state(patch), settings);
  const Eigen::Vector3d start = patch.positions.col(node),
                        n = patch.normals[patch.regions.of(node).front()];
  double b = 0, c = loop.turn_travel;
  for (const PullLoopSample& s : loop.samples)
    if (s.phase == PullPhase::loading) b = s.travel;
  const SeparationState fresh = make_separation_state(patch);
  SeparationState separation = fresh;
  SeparationContact contact;
  double travel = c;
  long tears = 0;
  for (auto _ : state) {
    if (travel >= c) {  // a new pull, loaded up to B
      separation = fresh;
      contact = begin_contact(patch, ContactMode::grasp, contact_at_node(patch, node), start);
      step_contact(patch, separation, contact, start + b * n);
      travel = b;
    }
    travel += 1e-5;
    const auto begin = std::chrono::steady_clock::now();
    const SeparationSample s = step_contact(patch, separation, contact, start + travel * n);
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count());
    tears += s.separated > 0;
  }
  set_counters(state, patch);
  state.counters["tearing_share"] =
      static_cast<double>(tears) / static_cast<double>(state.iterations());
}

// A tool under an opened flap (the strip x < 10 mm separated) pressing it up and dragged to
// and fro along y: it slides by friction every tick (a walk over the patch, an energy check).
void BM_SeparationTick_sliding(benchmark::State& state) {
  const SeparationPatch& patch = layers(static_cast<int>(state.range(0))).patch;
  SeparationState separation = make_separation_state(patch);
  std::vector<int> strip;
  for (int t = 0; t < patch.triangle_count(); ++t)
    if (patch.centroids[t].x() < 0.010) strip.push_back(t);
  separate_triangles(patch, separation, strip);
  const int node = nearest_patch_node(patch, Eigen::Vector3d(0.006, 0.02, 0));
  const Eigen::Vector3d start = patch.positions.col(node);
  SeparationContact contact =
      begin_contact(patch, ContactMode::push, contact_at_node(patch, node), start);
  int i = 0;
  long slides = 0;
  for (auto _ : state) {
    const double t = 1e-3 * i++;
    const Eigen::Vector3d tool = start + Eigen::Vector3d(0, 0.005 * std::sin(2 * t), 0.001);
    slides += (step_contact(patch, separation, contact, tool).flags & kSeparationSliding) != 0;
  }
  set_counters(state, patch);
  state.counters["sliding_share"] =
      static_cast<double>(slides) / static_cast<double>(state.iterations());
}

// A laser sweep at half the vaporisation speed across the interface.
void BM_SeparationTick_laser(benchmark::State& state) {
  const SeparationPatch& patch = layers(static_cast<int>(state.range(0))).patch;
  SeparationState separation = make_separation_state(patch);
  LaserFibre fibre;
  const double step = 0.5 * patch.vaporisation_speed * 1e-3;
  int i = 0;
  for (auto _ : state) {
    const double y = 0.001 + step * (i++ % static_cast<int>(0.038 / step));
    benchmark::DoNotOptimize(
        step_laser(patch, separation, fibre, Eigen::Vector3d(0.0203, y, 0), true, 1e-3).vaporised);
  }
  set_counters(state, patch);
}

// A pushing tool (contact: push) 2 mm above the middle of the interface, out of its 1 mm
// reach, moving in small circles: every tick looks for the nearest interface point over all
// the patch's triangles, to touch as soon as it comes within reach.
void BM_SeparationTick_pusher_hovering(benchmark::State& state) {
  const SeparationPatch& patch = layers(static_cast<int>(state.range(0))).patch;
  SeparationState separation = make_separation_state(patch);
  SeparationToolState tool;
  const SeparationToolSettings pusher{.contact = ContactMode::push};
  int i = 0;
  for (auto _ : state) {
    const double t = 1e-3 * (i++ % 6283);
    const Eigen::Vector3d tip(0.02 + 1e-3 * std::cos(t), 0.02 + 1e-3 * std::sin(t), 0.002);
    benchmark::DoNotOptimize(
        step_separation_tool(patch, separation, tool, pusher, tip, 0, 1e-3).distance);
  }
  set_counters(state, patch);
}

// The naive way: the force from a live sparse FEM solve of both layers, with the pairs
// that are still connected merged, factorised for the tool's node: every tick.
void BM_SeparationTick_naive_full_solve(benchmark::State& state) {
  const SeparationSetup& setup = layers(static_cast<int>(state.range(0)));
  const int node = nearest_patch_node(setup.patch, Eigen::Vector3d(0.0203, 0.0197, 0));
  const std::vector<bool> tied(static_cast<std::size_t>(setup.interface.node_count()), true);
  const std::vector<int> footprint{node};
  int i = 0;
  for (auto _ : state) {
    const double t = 1e-3 * i++;
    const std::vector<Eigen::Vector3d> delta{1e-3 * Eigen::Vector3d(std::cos(t), std::sin(t), 0.5)};
    const TiedSystem system = tied_system(setup.bodies, setup.interface, tied);
    benchmark::DoNotOptimize(footprint_forces(system, setup.interface, footprint, delta));
  }
  set_counters(state, setup.patch);
}

// The whole precomputation (two CHOLMOD factorisations, interface compliance, the tie
// inverse, every field's stiffness and fit), per field.
void BM_SeparationPrecompute(benchmark::State& state) {
  const TwoLayerBoxes b = boxes(static_cast<int>(state.range(0)));
  const SeparationBodies bodies = make_two_layer_boxes(b);
  const SeparationInterface interface = find_interface(bodies, 1e-9);
  FieldPrecomputeReport report;
  for (auto _ : state)
    benchmark::DoNotOptimize(
        precompute_separation_fields(bodies, interface, FieldSettings{}, &report).values.data());
  state.counters["patch_nodes"] = interface.node_count();
  state.counters["fields"] = report.field_count;
  state.counters["compliance_ms"] = 1e3 * report.compliance_seconds;
  state.counters["tie_ms"] = 1e3 * report.tie_seconds;
  state.counters["stiffness_ms"] = 1e3 * report.stiffness_seconds;
  state.counters["fit_ms"] = 1e3 * report.fit_seconds;
  state.counters["us_per_field"] = 1e6 * report.total_seconds() / report.field_count;
}

BENCHMARK(BM_SeparationTick_elastic)->Arg(10)->Arg(20)->Arg(30)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SeparationTick_tearing)
    ->Arg(10)
    ->Arg(20)
    ->Arg(30)
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SeparationTick_sliding)->Arg(10)->Arg(20)->Arg(30)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SeparationTick_laser)->Arg(10)->Arg(20)->Arg(30)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SeparationTick_pusher_hovering)
    ->Arg(10)
    ->Arg(20)
    ->Arg(30)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SeparationTick_naive_full_solve)->Arg(10)->Arg(20)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SeparationPrecompute)
    ->Arg(10)
    ->Arg(20)
    ->Arg(30)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
}  // namespace cohaptic
