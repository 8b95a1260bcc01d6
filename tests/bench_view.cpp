// What the live view costs the simulation: the server's simulation loop on the brain scene,
// its two tools following the demo's surgeons' scripted motions (scenes/brain/surgeon_*.yaml,
// the same window of them in every run), stepped as fast as it goes, with
//   - no view (BM_SimulationSteps/no_view), the reference;
//   - the live view at 30 frames/s and 0, 1 or 50 browsers (WebSocket clients in this
//     process, reading everything) connected: BM_SimulationSteps/view_browsers/N;
//   - no view, but a thread on the browsers' CPU burning CPU for P per mille of every
//     millisecond: BM_SimulationSteps_no_view_with_load/P, the control. The simulation does
//     nothing for the browsers, yet its steps slowed with 50 of them; this separates what
//     any work on the other CPU costs it (shared caches, memory bandwidth, a sibling
//     hyperthread of this VM) from what the view's own work does: compare the cases whose
//     others_cpu_us_per_step match (P = 50: about what the view and its 50 browsers take).
// And as the server runs it, the rate a user gets: SimulationLoop::run paced at its 1 kHz on
// its own thread for 10 s of wall time, the motions fed every millisecond as the I/O thread
// would, with no view (BM_SimulationRate_paced_no_view) or the view and 0, 1 or 50 browsers
// (BM_SimulationRate_paced_view_browsers/N). Counters: steps_per_s, rate_vs_1kHz_pct (the
// rate against the 1 kHz the loop aims at), and the browsers' frames and kB per second.
// A browser runs on another machine in real use. Here the browsers share this one, and the
// kernel charges a loopback receive to whichever thread happens to run, so the benchmark
// pins the simulation (this thread) to CPU 0 and the view's thread and the browsers to
// CPU 1 (on a machine with both): it then measures what the view costs the simulation
// thread itself, as on a server whose browsers are elsewhere.
// Time: real time per step; CPU: the simulation thread's own CPU time per step
// (CLOCK_THREAD_CPUTIME_ID); items_per_second: the step rate. Counters: others_cpu_us_per_step,
// the CPU of every other thread of the process (the view's, the browsers') per step; per
// browser, the frames and kB it received per second; the frames the view built and dropped.
//
// What one frame costs each thread, at one state of the same motions (both surgeons
// pressing, 3 s in), CPU time per frame:
//   - BM_ViewFrame_simulation_thread: the simulation thread's part, the state solve, its
//     loads (LoadedColumn) and the FrameState handed over (its one body's);
//   - BM_ViewFrame_view_thread: the view's thread's part, the shown surface's displacement
//     from those loads, the Frame and its encoding;
//   - BM_ViewFrame_displacement_from_loads: of which the displacement;
//   - BM_ViewFrame_displacement_gathered: the displacement as the display solves it
//     (Simulation::displacement_of: the state solve and a gathered block of L), which the
//     simulation thread solved for every view frame, and encoded, before the view's thread
//     took the frame over.
#include <array>
#include <benchmark/benchmark.h>

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>

#include <atomic>
#include <cmath>
#include <memory>
#include <optional>
#include <spdlog/spdlog.h>
#include <thread>

#include "common/haptics/trajectory.h"
#include "common/model/compliance_setup.h"
#include "common/scene/load_scene.h"
#include "common/sim/elastic_states.h"
#include "common/sim/ir_build_options.h"
#include "common/sim/loaded_columns.h"
#include "common/sim/scene_simulation.h"
#include "common/util/blas_threads.h"
#include "common/util/monotonic_clock.h"
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
    columns = std::make_unique<ComplianceColumns>(
        body.free_factor, body.dofs, compliance_row_nodes(body, !model->obstacles.empty()));
    prepare_compliance(body, *columns, default_cache_directory());
    for (const char* user : {"surgeon_a.yaml", "surgeon_b.yaml"})
      motions.push_back(load_trajectory(kBrain / "brain" / user));
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
    tools.update(static_cast<int>(slot), true, motion.position(std::fmod(t, motion.duration())), 0,
                 monotonic_now_ns(), monotonic_now_ns());
  }
}

// Pins the calling thread (and the threads it starts from now on) to `cpu`, if this process
// may run on CPUs 0 and 1; restores the thread's CPUs when it goes.
class PinnedThread {
 public:
  static bool possible() {
    cpu_set_t allowed;
    return sched_getaffinity(0, sizeof allowed, &allowed) == 0 && CPU_ISSET(0, &allowed) &&
           CPU_ISSET(1, &allowed);
  }
  explicit PinnedThread(int cpu) {
    pthread_getaffinity_np(pthread_self(), sizeof before_, &before_);
    cpu_set_t only;
    CPU_ZERO(&only);
    CPU_SET(cpu, &only);
    pthread_setaffinity_np(pthread_self(), sizeof only, &only);
  }
  ~PinnedThread() { pthread_setaffinity_np(pthread_self(), sizeof before_, &before_); }
  PinnedThread(const PinnedThread&) = delete;
  PinnedThread& operator=(const PinnedThread&) = delete;

 private:
  cpu_set_t before_;
};

// User and system CPU time so far [s] of the process (RUSAGE_SELF) or this thread
// (RUSAGE_THREAD), from the same accounting.
double cpu_seconds(int who) {
  rusage usage{};
  getrusage(who, &usage);
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

// A thread on `cpu` that, in every 1 ms slice, busy-loops for `per_mille` of it over a few
// MB of memory (more than a core's cache, as the browsers' buffers are), then sleeps to the
// next slice: other work on that CPU, at a set duty cycle, that the simulation does not use.
class CpuBurner {
 public:
  CpuBurner(int cpu, int per_mille)
      : thread_([this, cpu, per_mille] {
          const PinnedThread pinned(cpu);
          constexpr std::chrono::microseconds kSlice{1000};
          const auto busy = kSlice * per_mille / 1000;
          std::vector<std::uint64_t> memory(std::size_t{4} << 20 >> 3);
          std::size_t next = 0;
          for (auto slice = std::chrono::steady_clock::now();
               !stop_.load(std::memory_order_relaxed); slice += kSlice) {
            const auto woke = std::chrono::steady_clock::now();  // late by the timer's slack
            while (std::chrono::steady_clock::now() < woke + busy)
              for (int k = 0; k < 256; ++k, next = (next + 8) % memory.size())
                ++memory[next];  // one cache line each
            std::this_thread::sleep_until(slice + kSlice);
          }
          benchmark::DoNotOptimize(memory.data());
        }) {}
  ~CpuBurner() {
    stop_ = true;
    thread_.join();
  }
  CpuBurner(const CpuBurner&) = delete;
  CpuBurner& operator=(const CpuBurner&) = delete;

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// What runs beside the simulation loop: the live view with `browsers` connected, or not,
// and a CpuBurner at `load_per_mille` (0: none) on the view's CPU.
struct Beside {
  bool view = false;
  int browsers = 0;
  int load_per_mille = 0;
};

// The server's simulation loop on the brain with what runs beside it: the live view and its
// browsers on CPU 1 (when the machine has it), a burner there, and the simulation's thread
// to be pinned to CPU 0 by whoever steps it.
class LoopBeside {
 public:
  LoopBeside(benchmark::State& state, Beside beside)
      : rig_(BrainRig::get()), tools_(rig_.motions.size()) {
    if (!pin_) state.SetLabel("not pinned: CPUs 0 and 1 are not both available");
    options_.client_timeout_s = 3600;
    for (std::size_t slot = 0; slot < rig_.motions.size(); ++slot)
      tools_.join(static_cast<int>(slot));
    if (beside.view)
      live_ = std::make_unique<view::LiveView>(*rig_.model, std::array{rig_.columns.get()},
                                               wire_protocol(options_), injected_delays(options_),
                                               view::LiveViewOptions{}, nullptr);
    loop_ = std::make_unique<SimulationLoop>(*rig_.model, std::array{rig_.columns.get()}, options_,
                                             tools_, statistics_, nullptr, live_.get(), nullptr,
                                             monotonic_now_ns());
    // Once along the whole motion first: every compliance column it needs is computed (or
    // loaded) before the clock runs.
    for (double t = 0; t < rig_.motions[0].duration(); t += 0.005) {
      set_tools(tools_, rig_, t);
      loop_->step(monotonic_now_ns());
    }
    if (live_) {
      std::optional<PinnedThread> on_cpu1;  // the view's thread and the browsers' start there
      if (pin_) on_cpu1.emplace(1);
      live_->start();
      const std::string url = "ws://127.0.0.1:" + std::to_string(live_->port()) + "/ws";
      for (int k = 0; k < beside.browsers; ++k) {
        clients_.push_back(std::make_unique<testing::WebSocketClient>(url));
        if (!clients_.back()->wait_open(std::chrono::seconds(10)))
          state.SkipWithError("a browser could not connect");
        clients_.back()->count_only();
      }
    }
    if (beside.load_per_mille > 0) load_.emplace(pin_ ? 1 : 0, beside.load_per_mille);
  }
  ~LoopBeside() {
    clients_.clear();
    if (live_) live_->stop();
  }
  LoopBeside(const LoopBeside&) = delete;
  LoopBeside& operator=(const LoopBeside&) = delete;

  /// Pins the calling thread, the simulation's, to CPU 0 while `pinned` lives, when the
  /// machine has CPUs 0 and 1.
  void pin_simulation(std::optional<PinnedThread>& pinned) const {
    if (pin_) pinned.emplace(0);
    std::this_thread::yield();  // on CPU 0 from here
  }
  /// Starts the window whose browser figures report_browsers() gives.
  void start_window() {
    frames_before_.clear();
    bytes_before_.clear();
    for (const auto& client : clients_) {
      frames_before_.push_back(client->message_count());
      bytes_before_.push_back(client->bytes_received());
    }
    built_before_ = live_ ? live_->frames_built() : 0;
  }
  /// The view's frames and each browser's frames and kB per second over the window.
  void report_browsers(benchmark::State& state, double elapsed_s) const {
    if (live_)
      state.counters["frames_built_per_s"] =
          static_cast<double>(live_->frames_built() - built_before_) / elapsed_s;
    if (clients_.empty()) return;
    double frames = 0, bytes = 0;
    for (std::size_t k = 0; k < clients_.size(); ++k) {
      frames += static_cast<double>(clients_[k]->message_count() - frames_before_[k]);
      bytes += static_cast<double>(clients_[k]->bytes_received() - bytes_before_[k]);
    }
    state.counters["frames_per_s_per_browser"] =
        frames / static_cast<double>(clients_.size()) / elapsed_s;
    state.counters["kB_per_s_per_browser"] =
        bytes / static_cast<double>(clients_.size()) / elapsed_s / 1e3;
    state.counters["dropped"] = static_cast<double>(live_->counters().dropped);
  }

  BrainRig& rig() { return rig_; }
  ToolInputs& tools() { return tools_; }
  SimulationLoop& loop() { return *loop_; }
  const LoopStatistics& statistics() const { return statistics_; }

 private:
  BrainRig& rig_;
  const bool pin_ = PinnedThread::possible();
  ServeOptions options_;
  ToolInputs tools_;
  LoopStatistics statistics_;
  std::unique_ptr<view::LiveView> live_;
  std::unique_ptr<SimulationLoop> loop_;
  std::vector<std::unique_ptr<testing::WebSocketClient>> clients_;
  std::optional<CpuBurner> load_;
  std::vector<std::uint64_t> frames_before_, bytes_before_;
  std::uint64_t built_before_ = 0;
};

// Steps as fast as they go, the motion at a fixed stride: the time a step takes.
void run_steps(benchmark::State& state, Beside beside) {
  LoopBeside session(state, beside);
  std::optional<PinnedThread> on_cpu0;
  session.pin_simulation(on_cpu0);
  session.start_window();
  const double process_cpu_before = cpu_seconds(RUSAGE_SELF),
               thread_cpu_before = cpu_seconds(RUSAGE_THREAD);
  const auto start = std::chrono::steady_clock::now();
  double t = kWindowStart_s;
  for (auto _ : state) {
    set_tools(session.tools(), session.rig(), t);
    benchmark::DoNotOptimize(session.loop().step(monotonic_now_ns()));
    t += kWindowStride_s;  // the motion at a fixed stride, whatever the steps cost
  }
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double others_cpu = (cpu_seconds(RUSAGE_SELF) - process_cpu_before) -
                            (cpu_seconds(RUSAGE_THREAD) - thread_cpu_before);
  state.SetItemsProcessed(state.iterations());
  state.counters["others_cpu_us_per_step"] =
      1e6 * others_cpu / static_cast<double>(state.iterations());
  session.report_browsers(state, elapsed);
}

// As the server runs it: SimulationLoop::run paced at its 1 kHz on its own thread (pinned to
// CPU 0), for kPacedWindow of wall time, while this thread feeds the surgeons' motions as
// the I/O thread would, every millisecond. What the view may cost here is the rate itself:
// steps that overrun their period push the next ones later (no catch-up burst).
constexpr std::chrono::seconds kPacedWindow{10};

void run_paced(benchmark::State& state, Beside beside) {
  LoopBeside session(state, beside);
  for (auto _ : state) {
    set_tools(session.tools(), session.rig(), kWindowStart_s);
    const LoopSummary before = session.statistics().summary();
    session.start_window();
    std::atomic<bool> running{true};
    std::thread simulation([&] {
      std::optional<PinnedThread> on_cpu0;
      session.pin_simulation(on_cpu0);
      session.loop().run(running, [](Outbox&&) {});
    });
    const auto start = std::chrono::steady_clock::now();
    for (auto now = start; now - start < kPacedWindow; now = std::chrono::steady_clock::now()) {
      const double t =
          kWindowStart_s + std::fmod(std::chrono::duration<double>(now - start).count(),
                                     static_cast<double>(kWindowSteps) * kWindowStride_s);
      set_tools(session.tools(), session.rig(), t);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    running = false;
    simulation.join();
    const LoopSummary after = session.statistics().summary();
    const double elapsed = after.elapsed_s - before.elapsed_s;
    const double rate = static_cast<double>(after.steps - before.steps) / elapsed;
    state.SetIterationTime(elapsed);
    state.counters["steps_per_s"] = rate;
    state.counters["rate_vs_1kHz_pct"] = 100.0 * (rate / kDefaultSimulationRate_hz - 1.0);
    state.counters["step_p99_ms"] = after.step_p99_ms;  // of every step, the warm-up's included
    session.report_browsers(state, elapsed);
  }
}

// The brain with both surgeons pressing, 3 s into their motions, and what a frame of it needs.
struct PressedBrain {
  BrainRig& rig = BrainRig::get();
  std::array<ComplianceColumns*, 1> columns{rig.columns.get()};
  SceneSimulation scene;
  Simulation& simulation;
  view::ShownScene shown;
  std::vector<view::ToolState> tools;
  std::vector<Eigen::Vector3d> forces;
  static SimulationOptions options(const Model& model) {
    SimulationOptions options;
    options.ir = ir_build_options(model.scene.haptic);
    return options;
  }
  PressedBrain()
      : scene(*rig.model, columns, rig.model->scene.tools, options(*rig.model)),
        simulation(scene.single_elastic()),
        shown(view::shown_scene(*rig.model, columns)) {
    for (double t = 0; t < 3.0; t += 0.005) {
      for (std::size_t slot = 0; slot < rig.motions.size(); ++slot)
        scene.set_tool(static_cast<int>(slot), rig.motions[slot].position(t));
      scene.step(t);
    }
    for (std::size_t slot = 0; slot < rig.motions.size(); ++slot) {
      tools.push_back({true, rig.motions[slot].position(3.0)});
      forces.push_back(simulation.force(static_cast<int>(slot)).force);
    }
  }
  static PressedBrain& get() {
    static PressedBrain brain;
    return brain;
  }
  view::FrameState frame_state() {
    return view::frame_state(scene, columns, solve_elastic_states(scene), tools, forces);
  }
  void describe(benchmark::State& state) {
    state.counters["pressing"] = simulation.pressing(0) + simulation.pressing(1);
    state.counters["boundary_nodes"] =
        static_cast<double>(simulation.condensation().boundary_nodes().size());
    state.counters["shown_nodes"] = static_cast<double>(shown.node_count());
  }
};

void BM_ViewFrame_simulation_thread(benchmark::State& state) {
  PressedBrain& brain = PressedBrain::get();
  for (auto _ : state) benchmark::DoNotOptimize(brain.frame_state());
  brain.describe(state);
}

void BM_ViewFrame_view_thread(benchmark::State& state) {
  PressedBrain& brain = PressedBrain::get();
  const view::FrameState frame = brain.frame_state();
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::string message =
        view::server_message(view::view_frame(frame, brain.shown, 1, 3.0, 400));
    bytes = message.size();
    benchmark::DoNotOptimize(message.data());
  }
  state.counters["frame_kB"] = static_cast<double>(bytes) / 1e3;
}

void BM_ViewFrame_displacement_from_loads(benchmark::State& state) {
  PressedBrain& brain = PressedBrain::get();
  const view::FrameState frame = brain.frame_state();
  for (auto _ : state)
    benchmark::DoNotOptimize(
        displacement_of_rows(std::get<view::ElasticFrameState>(frame.bodies.front()).loads,
                             brain.shown.parts.front().row_positions));
}

void BM_ViewFrame_displacement_gathered(benchmark::State& state) {
  PressedBrain& brain = PressedBrain::get();
  for (auto _ : state)
    benchmark::DoNotOptimize(brain.simulation.displacement_of(brain.shown.parts.front().nodes));
}

BENCHMARK(BM_ViewFrame_simulation_thread)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ViewFrame_view_thread)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ViewFrame_displacement_from_loads)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ViewFrame_displacement_gathered)->Unit(benchmark::kMicrosecond);

void BM_SimulationSteps_no_view(benchmark::State& state) { run_steps(state, {}); }
void BM_SimulationSteps_view_browsers(benchmark::State& state) {
  run_steps(state, {.view = true, .browsers = static_cast<int>(state.range(0))});
}
void BM_SimulationSteps_no_view_with_load(benchmark::State& state) {
  run_steps(state, {.load_per_mille = static_cast<int>(state.range(0))});
}

void BM_SimulationRate_paced_no_view(benchmark::State& state) { run_paced(state, {}); }
void BM_SimulationRate_paced_view_browsers(benchmark::State& state) {
  run_paced(state, {.view = true, .browsers = static_cast<int>(state.range(0))});
}

BENCHMARK(BM_SimulationSteps_no_view)
    ->Iterations(kWindowSteps)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK(BM_SimulationSteps_view_browsers)
    ->Arg(0)
    ->Arg(1)
    ->Arg(50)
    ->Iterations(kWindowSteps)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK(BM_SimulationSteps_no_view_with_load)
    ->Arg(50)
    ->Arg(90)
    ->Arg(300)
    ->Iterations(kWindowSteps)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

BENCHMARK(BM_SimulationRate_paced_no_view)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kSecond);
BENCHMARK(BM_SimulationRate_paced_view_browsers)
    ->Arg(0)
    ->Arg(1)
    ->Arg(50)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kSecond);

}  // namespace
}  // namespace cohaptic
