// The client's haptic loop in process, with a scripted device and an IR from the
// simulation: the force it outputs is the evaluator's, limited and faded as specified,
// zero for non-finite input, and its schedule keeps its phase. Most tests drive the loop's
// clock (DrivenClock), so each tick happens at an exact time whatever the machine's load;
// one fade test and one late-tick test run on the real clock.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <limits>
#include <thread>

#include "client/haptic_loop.h"
#include "common/haptics/scripted_device.h"
#include "common/haptics/trajectory.h"
#include "common/scene/load_scene.h"
#include "common/sim/simulation.h"
#include "common/util/monotonic_clock.h"
#include "support/cube_scene.h"
#include "support/driven_clock.h"
#include "support/evaluate_static.h"

namespace cohaptic {
namespace {

using namespace std::chrono_literals;
using testing::DrivenClock;

// A device whose pose becomes NaN after `nan_after_s`.
class NanDevice final : public HapticDevice {
 public:
  explicit NanDevice(double nan_after_s) : nan_after_s_(nan_after_s) {}
  std::string describe() const override { return "nan"; }
  DeviceState read(double t) override {
    DeviceState s;
    s.position =
        t < nan_after_s_ ? Eigen::Vector3d(0.001, 0.002, -0.002) : Eigen::Vector3d::Constant(NAN);
    return s;
  }
  void write_force(const Eigen::Vector3d& f, double) override { last = f; }
  double force_limit() const override { return 10; }
  Eigen::Vector3d last = Eigen::Vector3d::Zero();

 private:
  double nan_after_s_;
};

struct Fixture {
  testing::CubeRig rig{[] {
    testing::CubeSceneOptions o;
    o.divisions = 6;
    o.youngs_modulus = 2e4;
    return o;
  }()};
  std::shared_ptr<const PreparedIR> ir_for(const Eigen::Vector3d& tool) {
    SimulationOptions options;
    options.ir.force_limit = std::numeric_limits<double>::infinity();
    Simulation simulation(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(1),
                          options);
    simulation.set_tool(0, tool);
    simulation.step(0);
    return simulation.ir(0);
  }
  // A tool pressed 2 mm in, its IR and the force the evaluator gives there.
  const Eigen::Vector3d pressed{0.001, 0.002, -0.002};
  const std::shared_ptr<const PreparedIR> ir = ir_for(pressed);
  const Eigen::Vector3d pressed_force = testing::evaluate_static(*ir, pressed, {}).force;
  /// Channels with tracing on, holding the pressed IR as arrived at `arrival_ns`.
  std::unique_ptr<HapticChannels> channels_with_ir(std::int64_t arrival_ns) const {
    auto channels = std::make_unique<HapticChannels>();
    channels->tracing = true;
    channels->ir.back() = make_ir_slot(std::make_unique<const PreparedIR>(*ir), arrival_ns);
    channels->ir.publish();
    return channels;
  }
  /// A scripted device holding the tool where it is pressed.
  static ScriptedDevice holding_device() {
    return ScriptedDevice(
        parse_trajectory("units: m\nstart: [0.001, 0.002, -0.002]\nsegments: [{hold: 10}]\n",
                         "hold"),
        10);
  }
};

std::vector<TickRecord> drain(HapticChannels& channels) {
  std::vector<TickRecord> ticks;
  while (const auto t = channels.trace.pop()) ticks.push_back(*t);
  return ticks;
}

// Runs `loop` to its end (its duration, or its device's) and returns the ticks it traced.
std::vector<TickRecord> run_to_end(HapticLoop& loop, HapticChannels& channels) {
  const std::atomic<bool> stop{false};
  loop.run(stop);
  return drain(channels);
}

constexpr std::int64_t kMs = 1'000'000;  // [ns]

// On a driven clock: confirmations every 10 ms until 200 ms, then none. The force is the
// evaluator's times a fade of exactly 1 up to an age of max_age (100 ms), then falling on a
// straight line to 0 at max_age + fade (150 ms), and 0 after.
TEST(HapticLoop, FadesTheForceLinearlyFromMaxAgeToZeroOnADrivenClock) {
  const Fixture fixture;
  const Eigen::Vector3d& expected = fixture.pressed_force;
  ASSERT_GT(expected.norm(), 0.2);
  DrivenClock clock;
  const std::int64_t start = clock.now;
  const std::unique_ptr<HapticChannels> channels = fixture.channels_with_ir(start);
  clock.at = [&](std::int64_t now) {
    if ((now - start) % (10 * kMs) == 0 && now - start <= 200 * kMs) {
      channels->confirmation.back() = {fixture.ir->ir.epoch, now};
      channels->confirmation.publish();
    }
  };
  ScriptedDevice device = Fixture::holding_device();
  HapticLoopSettings settings;
  settings.force_limit = 10;  // above the evaluated force: what comes out is the fade alone
  settings.max_age_s = 0.1;
  settings.fade_s = 0.05;
  settings.duration_s = 0.5;
  settings.realtime = false;
  HapticLoop loop(device, *channels, settings, clock.haptic());
  const std::vector<TickRecord> ticks = run_to_end(loop, *channels);
  ASSERT_EQ(ticks.size(), 499u) << "a tick every 1 ms from 1 ms, until 0.5 s";
  EXPECT_EQ(loop.metrics().missed_deadlines, 0u);
  int fading = 0;
  for (const TickRecord& t : ticks) {
    const std::int64_t ms = (t.time_ns - start) / kMs;
    ASSERT_EQ(t.time_ns, start + ms * kMs) << "on the 1 ms grid";
    const std::int64_t age_ms = ms - std::min<std::int64_t>(ms / 10 * 10, 200);
    const double fade =
        age_ms <= 100 ? 1.0 : std::max(0.0, static_cast<double>(150 - age_ms) / 50.0);
    EXPECT_EQ(t.evaluated, expected) << "at " << ms << " ms";
    EXPECT_FLOAT_EQ(t.fade, static_cast<float>(fade))
        << "at " << ms << " ms, " << age_ms << " ms after the last confirmation";
    EXPECT_EQ(t.force, expected * static_cast<double>(t.fade)) << "at " << ms << " ms";
    if (fade > 0 && fade < 1) ++fading;
  }
  EXPECT_EQ(fading, 49) << "ages 101 to 149 ms";
  // By hand: the last confirmation came at 200 ms; the fade is 0.8, 0.5 and 0.2 at 10, 25
  // and 40 ms into its 50 ms.
  for (const auto& [ms, fade] :
       {std::pair{300, 1.0f}, {310, 0.8f}, {325, 0.5f}, {340, 0.2f}, {350, 0.0f}})
    EXPECT_FLOAT_EQ(ticks[static_cast<std::size_t>(ms - 1)].fade, fade) << ms << " ms";
  EXPECT_EQ(device.last_force(), Eigen::Vector3d::Zero())
      << "the loop leaves the device at zero force";
  // The user felt one fade, from 301 ms to the end (499 ms), the faded-out ticks included.
  EXPECT_EQ(loop.metrics().fades.count, 1u);
  EXPECT_NEAR(loop.metrics().fades.total_s, 0.199, 1e-9);
  EXPECT_NEAR(loop.metrics().fades.longest_s, 0.199, 1e-9);
}

// On a driven clock: the server confirms the IR every 10 ms until 200 ms, then builds a newer
// one and confirms that, which never arrives. The IR in use ages from its last confirmation,
// not from its arrival 200 ms before: full force until 300 ms (max_age 100 ms), then the fade.
TEST(HapticLoop, WhileANewerIrIsOnItsWayTheOneInUseAgesFromItsLastConfirmation) {
  const Fixture fixture;
  DrivenClock clock;
  const std::int64_t start = clock.now;
  const std::unique_ptr<HapticChannels> channels = fixture.channels_with_ir(start);
  clock.at = [&](std::int64_t now) {
    if ((now - start) % (10 * kMs) != 0 || now - start > 400 * kMs) return;
    channels->confirmation.back() = {fixture.ir->ir.epoch + (now - start <= 200 * kMs ? 0 : 1),
                                     now};
    channels->confirmation.publish();
  };
  ScriptedDevice device = Fixture::holding_device();
  HapticLoopSettings settings;
  settings.force_limit = 10;
  settings.max_age_s = 0.1;
  settings.fade_s = 0.05;
  settings.duration_s = 0.4;
  settings.realtime = false;
  HapticLoop loop(device, *channels, settings, clock.haptic());
  const std::vector<TickRecord> ticks = run_to_end(loop, *channels);
  ASSERT_EQ(ticks.size(), 399u);
  for (const auto& [ms, fade] :
       {std::pair{150, 1.0f}, {250, 1.0f}, {300, 1.0f}, {310, 0.8f}, {325, 0.5f}, {350, 0.0f}})
    EXPECT_FLOAT_EQ(ticks[static_cast<std::size_t>(ms - 1)].fade, fade) << ms << " ms";
}

// On the real clock (CLOCK_MONOTONIC, a thread confirming), with the force limited. The
// confirmations come when the machine lets them, so each tick is judged by the ones it
// surely saw: full force within max_age of a confirmation published before the tick woke,
// zero once max_age + fade have passed since the last one.
TEST(HapticLoop, OutputsTheEvaluatorsForceLimitedAndFadedWhenConfirmationsStop) {
  const Fixture fixture;
  const Eigen::Vector3d& expected = fixture.pressed_force;
  ASSERT_GT(expected.norm(), 0.2);
  const std::unique_ptr<HapticChannels> channels = fixture.channels_with_ir(monotonic_now_ns());
  ScriptedDevice device = Fixture::holding_device();
  HapticLoopSettings settings;
  settings.force_limit = 0.2;  // below the evaluated force: clamped
  settings.max_age_s = 0.1;
  settings.fade_s = 0.05;
  settings.duration_s =
      1.0;  // long after the confirmations stop, however late a loaded machine sends them
  settings.realtime = false;
  HapticLoop loop(device, *channels, settings);
  // Confirm the IR 20 times, every 10 ms, then go silent (as a dead server would): the
  // sleeps are the stimulus, a server's pace. Each confirmation's stamp and the time by
  // which it was published.
  struct Confirmed {
    std::int64_t stamp_ns = 0, published_ns = 0;
  };
  std::vector<Confirmed> confirmed(20);
  std::thread server([&] {
    for (Confirmed& c : confirmed) {
      c.stamp_ns = monotonic_now_ns();
      channels->confirmation.back() = {fixture.ir->ir.epoch, c.stamp_ns};
      channels->confirmation.publish();
      c.published_ns = monotonic_now_ns();
      std::this_thread::sleep_for(10ms);
    }
  });
  const std::vector<TickRecord> ticks = run_to_end(loop, *channels);
  server.join();
  ASSERT_GT(ticks.size(), 400u);

  const std::int64_t max_age_ns = 100 * kMs, faded_out_ns = 150 * kMs + 1000;  // + 1 us of rounding
  int full = 0, zero = 0;
  for (const TickRecord& t : ticks) {
    EXPECT_EQ(t.evaluated, expected);
    EXPECT_LE(t.force.norm(), 0.2 + 1e-12);
    const auto seen = std::find_if(confirmed.rbegin(), confirmed.rend(),
                                   [&](const Confirmed& c) { return c.published_ns <= t.time_ns; });
    if (seen != confirmed.rend() && t.time_ns - seen->stamp_ns <= max_age_ns) {
      EXPECT_EQ(t.fade, 1.0f) << static_cast<double>(t.time_ns - seen->stamp_ns) * 1e-6
                              << " ms after a confirmation it saw";
      ++full;
    }
    if (t.time_ns - confirmed.back().stamp_ns > faded_out_ns) {
      EXPECT_EQ(t.force.norm(), 0.0)
          << static_cast<double>(t.time_ns - confirmed.back().stamp_ns) * 1e-6
          << " ms after the last confirmation";
      ++zero;
    }
  }
  std::printf("  %zu ticks: %d at full force after a confirmation, %d at zero after the fade\n",
              ticks.size(), full, zero);
  EXPECT_GT(full, 100);
  EXPECT_GT(zero, 100);
  EXPECT_NEAR(ticks.front().force.norm(), 0.2, 1e-12);
  EXPECT_GT(loop.metrics().clamped, 0u);
  // Every 1 ms period of the 1 s run is either a tick or a skipped deadline (a loaded
  // machine skips some), so together they account for the duration.
  EXPECT_NEAR(static_cast<double>(loop.metrics().ticks + loop.metrics().missed_deadlines), 1000,
              25);
  EXPECT_EQ(device.last_force(), Eigen::Vector3d::Zero())
      << "the loop leaves the device at zero force";
}

TEST(HapticLoop, NonFiniteInputGivesZeroForceAndAnEvent) {
  const Fixture fixture;
  DrivenClock clock;
  const std::unique_ptr<HapticChannels> channels = fixture.channels_with_ir(clock.now);
  NanDevice device(0.1005);
  HapticLoopSettings settings;
  settings.duration_s = 0.2;
  settings.realtime = false;
  settings.max_age_s = 10;
  HapticLoop loop(device, *channels, settings, clock.haptic());
  int zero_after = 0;
  for (const TickRecord& t : run_to_end(loop, *channels)) {
    ASSERT_TRUE(t.force.allFinite());
    if (!t.own.allFinite()) {
      EXPECT_EQ(t.force, Eigen::Vector3d::Zero());
      EXPECT_TRUE(t.flags & kNonFinite);
      ++zero_after;
    }
  }
  EXPECT_EQ(zero_after, 99) << "the ticks at 101 to 199 ms";
}

// A sphere contact solve that runs out of its tick's work budget has no force of its own
// (the evaluator flags the tick): the loop holds the last resolved force (it does not move
// at the miss), never above the force limit, and counts the tick; the next ticks go on
// where the solve stopped, so the exact force returns within a few ticks. Here the tool
// jumps 3.5 mm deeper in one tick, a budget of 200 multiply-adds a tick (the haptic loop's
// is 1.5 million) makes the solve take many ticks, and the force is checked at every one.
TEST(HapticLoop, ASphereSolvePastItsBudgetHoldsTheLastResolvedForceAndCatchesUp) {
  testing::CubeSceneOptions cube;
  cube.divisions = 24;
  cube.tools = "[{name: A, shape: sphere, radius: 30}]";
  const testing::CubeRig rig(cube);
  SimulationOptions options;
  options.ir.contact_model = ContactModel::sphere;
  options.ir.patch_rings = 3;  // the deeper press stays within the IR's rows
  options.ir.force_limit = 1000;
  Simulation simulation(rig.body, rig.model->obstacles, *rig.columns, rig.model->scene.tools,
                        options);
  const Eigen::Vector3d shallow(0.001, 0.002, 0.0295),
      deep(0.001, 0.002, 0.026);  // 0.5 and 4 mm deep
  simulation.set_tool(0, shallow);
  simulation.step(0);
  const std::shared_ptr<const PreparedIR> ir = simulation.ir(0);
  const Eigen::Vector3d shallow_force = testing::evaluate_static(*ir, shallow, {}).force;
  const Eigen::Vector3d deep_force = testing::evaluate_static(*ir, deep, {}).force;
  ASSERT_GT(deep_force.norm(), 5 * shallow_force.norm());

  DrivenClock clock;
  auto channels = std::make_unique<HapticChannels>();
  channels->tracing = true;
  channels->ir.back() = make_ir_slot(std::make_unique<const PreparedIR>(*ir), clock.now);
  std::get<FemEvaluation>(channels->ir.back().state->body).sphere->work_budget = 200;
  channels->ir.publish();
  ScriptedDevice device(
      parse_trajectory(
          "units: mm\nstart: [1, 2, 29.5]\nsegments: [{hold: 0.05}, {move_to: [1, 2, 26], "
          "speed: 1e6}, {hold: 0.15}]\n",
          "jump"),
      1000);
  HapticLoopSettings settings;
  settings.duration_s = 0.2;
  settings.realtime = false;
  settings.max_age_s = 10;
  settings.force_limit = 30;
  HapticLoop loop(device, *channels, settings, clock.haptic());
  const std::vector<TickRecord> ticks = run_to_end(loop, *channels);
  ASSERT_GT(ticks.size(), 150u);
  int unresolved = 0, first_resolved_deep = -1;
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    const TickRecord& t = ticks[i];
    ASSERT_TRUE(t.force.allFinite()) << "tick " << i;
    ASSERT_LE(t.force.norm(), settings.force_limit * (1 + 1e-12)) << "tick " << i;
    if (t.flags & kContactUnresolved) {
      ++unresolved;
      ASSERT_GT(i, 0u);
      EXPECT_EQ(t.evaluated, ticks[i - 1].evaluated)
          << "tick " << i << ": the last resolved force is held";
    } else if ((t.own - deep).norm() < 1e-12 && first_resolved_deep < 0) {
      first_resolved_deep = static_cast<int>(i);
    }
  }
  std::printf("  %d ticks unresolved after the jump; resolved again %d ticks after it\n",
              unresolved, first_resolved_deep - 50);
  EXPECT_GT(unresolved, 2) << "the budget was never short";
  EXPECT_EQ(loop.metrics().contact_unresolved, static_cast<std::uint64_t>(unresolved));
  ASSERT_GE(first_resolved_deep, 0) << "the solve never caught up";
  EXPECT_LE((ticks.back().evaluated - deep_force).norm(), 1e-9 * deep_force.norm())
      << "the exact force returned";
  EXPECT_LE((ticks[40].evaluated - shallow_force).norm(), 1e-9 * shallow_force.norm());
}

// A device that stalls once, at its first read after 50 ms, like a host preempting the VM.
class StallingDevice final : public HapticDevice {
 public:
  explicit StallingDevice(std::function<void()> stall) : stall_(std::move(stall)) {}
  std::string describe() const override { return "stall"; }
  DeviceState read(double t) override {
    if (!stalled_ && t > 0.05) {
      stalled_ = true;
      stall_();
    }
    return {};
  }
  void write_force(const Eigen::Vector3d&, double) override {}
  double force_limit() const override { return 1; }

 private:
  std::function<void()> stall_;
  bool stalled_ = false;
};

TEST(HapticLoop, ALateTickSkipsTheMissedDeadlinesAndKeepsThePhase) {
  StallingDevice device([] { std::this_thread::sleep_for(5500us); });  // stimulus: the stall
  auto channels = std::make_unique<HapticChannels>();
  channels->tracing = true;
  HapticLoopSettings settings;
  settings.duration_s = 0.2;
  settings.realtime = false;
  HapticLoop loop(device, *channels, settings);
  const std::vector<TickRecord> ticks = run_to_end(loop, *channels);
  EXPECT_GE(loop.metrics().missed_deadlines, 4u);
  // The ticks after the stall are on the same 1 ms grid as those before it: their median
  // offset from the first tick's grid is the same (wake-up latency, which a loaded machine
  // raises for both alike), not shifted by the stall.
  const auto median_offset = [&](std::int64_t from_ns, std::int64_t to_ns) {
    std::vector<std::int64_t> offsets;
    for (const TickRecord& t : ticks) {
      const std::int64_t since = t.time_ns - ticks.front().time_ns;
      if (since < from_ns || since > to_ns) continue;
      std::int64_t offset = since % 1'000'000;
      if (offset > 500'000) offset -= 1'000'000;  // in (-0.5, 0.5] ms
      offsets.push_back(offset);
    }
    std::nth_element(offsets.begin(),
                     offsets.begin() + static_cast<std::ptrdiff_t>(offsets.size() / 2),
                     offsets.end());
    return offsets[offsets.size() / 2];
  };
  // The stall comes at 50 ms: before it, 0-45 ms; after it, from 70 ms.
  const std::int64_t before = median_offset(0, 45'000'000),
                     after = median_offset(70'000'000, 200'000'000);
  EXPECT_LT(std::abs(after - before), 300'000) << "median offset from the 1 ms grid: " << before
                                               << " ns before the stall, " << after << " ns after";
  EXPECT_LT(ticks.size(), 200u - 3u) << "missed ticks are skipped, not caught up";
}

// The same on a driven clock, exactly: the read at 51 ms stalls 5.5 ms, so the loop wakes
// at 56.5 ms for its 52 ms deadline. The deadlines 52 to 55 ms are skipped (4), the late
// tick runs at once, and every tick after it is back on the 1 ms grid at 57, 58, ... ms.
TEST(HapticLoop, ALateTickSkipsExactlyTheMissedDeadlinesOnADrivenClock) {
  DrivenClock clock;
  const std::int64_t start = clock.now;
  StallingDevice device([&clock] { clock.now += 5 * kMs + kMs / 2; });
  auto channels = std::make_unique<HapticChannels>();
  channels->tracing = true;
  HapticLoopSettings settings;
  settings.duration_s = 0.2;
  settings.realtime = false;
  HapticLoop loop(device, *channels, settings, clock.haptic());
  const std::vector<TickRecord> ticks = run_to_end(loop, *channels);
  EXPECT_EQ(loop.metrics().missed_deadlines, 4u);
  std::vector<std::int64_t> expected;  // tick times from the start [ns]
  for (std::int64_t ms = 1; ms <= 51; ++ms) expected.push_back(ms * kMs);
  expected.push_back(56 * kMs + kMs / 2);
  for (std::int64_t ms = 57; ms < 200; ++ms) expected.push_back(ms * kMs);
  std::vector<std::int64_t> times;
  for (const TickRecord& t : ticks) times.push_back(t.time_ns - start);
  EXPECT_EQ(times, expected);
  EXPECT_EQ(loop.metrics().ticks + loop.metrics().missed_deadlines, 199u)
      << "every period a tick or a skipped deadline";
}

}  // namespace
}  // namespace cohaptic
