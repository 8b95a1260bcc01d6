// What the live view costs the simulation: the server's simulation loop on the brain scene,
// its two tools following the demo's surgeons' scripted motions (scenes/brain/surgeon_*.yaml,
// the same window of them in every run), stepped as fast as it goes, with
//   - no view (BM_SimulationSteps/no_view), the reference;
//   - the live view at 30 frames/s and 0, 1 or 50 browsers (WebSocket clients in this
//     process, reading everything) connected: BM_SimulationSteps/view_browsers/N.
// items_per_second is the simulation's step rate; the counters give, per browser, the
// frames and bytes it received per second. The browsers and the view server's thread share
// the machine's cores with the simulation, as they would on a server with local browsers.
#include <array>
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <spdlog/spdlog.h>
#include <thread>

#include "common/haptics/trajectory.h"
#include "common/model/compliance_setup.h"
#include "common/scene/load_scene.h"
#include "common/util/blas_threads.h"
#include "proto/wire/header.h"
#include "server/server_recording.h"
#include "server/simulation_loop.h"
#include "support/websocket_client.h"
#include "view/live_view.h"

namespace cohaptic {
namespace {

const std::filesystem::path kBrain = std::filesystem::path(COHAPTIC_SOURCE_DIR) / "scenes";

struct BrainRig {
  std::unique_ptr<Model> model;
  std::unique_ptr<ComplianceColumns> columns;
  std::vector<Trajectory> motions;
  BrainRig() {
    spdlog::set_level(spdlog::level::warn);
    use_single_blas_thread();
    model = std::make_unique<Model>(build_model(load_scene(kBrain / "brain.yaml")));
    const ElasticBody& body = single_elastic_body(*model);
    columns = std::make_unique<ComplianceColumns>(*body.free_factor, body.dofs,
                                                  compliance_row_nodes(body, !model->obstacles.empty()));
    prepare_compliance(body, *columns, default_cache_directory());
    for (const char* user : {"surgeon_a.yaml", "surgeon_b.yaml"}) motions.push_back(load_trajectory(kBrain / "brain" / user));
  }
  static BrainRig& get() {
    static BrainRig rig;
    return rig;
  }
};

// Every configuration steps the same tool positions, so that they differ only by the view:
// a step's cost depends on the motion's phase (how many nodes are pressed or rest on the
// skull), and a time-limited run would cover a different part of the motion in each. The
// window is both surgeons' press and hold (0.4 s to 5.3 s of their scripts), every 2 ms.
constexpr double kWindowStart_s = 0.4, kWindowStride_s = 0.002;
constexpr benchmark::IterationCount kWindowSteps = 2450;

// Steps the loop as the server would, with the tools `t` seconds into their motions.
void set_tools(ToolInputs& tools, const BrainRig& rig, double t) {
  for (std::size_t slot = 0; slot < rig.motions.size(); ++slot) {
    const Trajectory& motion = rig.motions[slot];
    tools.update(static_cast<int>(slot), true, motion.position(std::fmod(t, motion.duration())), wire::monotonic_now_ns(),
                 wire::monotonic_now_ns());
  }
}

void run_steps(benchmark::State& state, bool with_view, int browsers) {
  BrainRig& rig = BrainRig::get();
  ServeOptions options;
  options.client_timeout_s = 3600;
  ToolInputs tools(rig.motions.size());
  for (std::size_t slot = 0; slot < rig.motions.size(); ++slot) tools.join(static_cast<int>(slot));
  LoopStatistics statistics;
  std::unique_ptr<view::LiveView> live;
  if (with_view)
    live = std::make_unique<view::LiveView>(*rig.model, *rig.columns, wire_protocol(options), injected_delays(options),
                                            view::LiveViewOptions{}, nullptr);
  SimulationLoop loop(*rig.model, std::array{rig.columns.get()}, options, tools, statistics, nullptr, live.get(), nullptr,
                      wire::monotonic_now_ns());
  // Once along the whole motion first: every compliance column it needs is computed (or
  // loaded) before the clock runs.
  for (double t = 0; t < rig.motions[0].duration(); t += 0.005) {
    set_tools(tools, rig, t);
    loop.step(wire::monotonic_now_ns());
  }
  std::vector<std::unique_ptr<testing::WebSocketClient>> clients;
  if (live) {
    live->start();
    const std::string url = "ws://127.0.0.1:" + std::to_string(live->port()) + "/ws";
    for (int k = 0; k < browsers; ++k) {
      clients.push_back(std::make_unique<testing::WebSocketClient>(url));
      if (!clients.back()->wait_open(std::chrono::seconds(10))) state.SkipWithError("a browser could not connect");
      clients.back()->count_only();
    }
  }
  std::vector<std::uint64_t> frames_before, bytes_before;
  for (const auto& client : clients) {
    frames_before.push_back(client->message_count());
    bytes_before.push_back(client->bytes_received());
  }
  const auto start = std::chrono::steady_clock::now();
  double t = kWindowStart_s;
  for (auto _ : state) {
    set_tools(tools, rig, t);
    benchmark::DoNotOptimize(loop.step(wire::monotonic_now_ns()));
    t += kWindowStride_s;  // the motion at a fixed stride, whatever the steps cost
  }
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  state.SetItemsProcessed(state.iterations());
  if (!clients.empty()) {
    double frames = 0, bytes = 0;
    for (std::size_t k = 0; k < clients.size(); ++k) {
      frames += static_cast<double>(clients[k]->message_count() - frames_before[k]);
      bytes += static_cast<double>(clients[k]->bytes_received() - bytes_before[k]);
    }
    state.counters["frames_per_s_per_browser"] = frames / static_cast<double>(clients.size()) / elapsed;
    state.counters["kB_per_s_per_browser"] = bytes / static_cast<double>(clients.size()) / elapsed / 1e3;
    state.counters["dropped"] = static_cast<double>(live->counters().dropped);
  }
  clients.clear();
  if (live) live->stop();
}

void BM_SimulationSteps_no_view(benchmark::State& state) { run_steps(state, false, 0); }
void BM_SimulationSteps_view_browsers(benchmark::State& state) { run_steps(state, true, static_cast<int>(state.range(0))); }

BENCHMARK(BM_SimulationSteps_no_view)->Iterations(kWindowSteps)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_SimulationSteps_view_browsers)
    ->Arg(0)
    ->Arg(1)
    ->Arg(50)
    ->Iterations(kWindowSteps)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

}  // namespace
}  // namespace cohaptic
