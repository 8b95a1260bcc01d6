// The client's haptic loop in process, with a scripted device and an IR from the
// simulation: the force it outputs is the evaluator's, limited and faded as specified,
// zero for non-finite input, and its schedule keeps its phase.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <thread>

#include "client/haptic_loop.h"
#include "common/haptics/scripted_device.h"
#include "common/haptics/trajectory.h"
#include "common/scene/load_scene.h"
#include "common/sim/simulation.h"
#include "support/cube_scene.h"

namespace cohaptic {
namespace {

using namespace std::chrono_literals;

// A device whose pose becomes NaN after `nan_after_s`.
class NanDevice final : public HapticDevice {
 public:
  explicit NanDevice(double nan_after_s) : nan_after_s_(nan_after_s) {}
  std::string describe() const override { return "nan"; }
  DeviceState read(double t) override {
    DeviceState s;
    s.position = t < nan_after_s_ ? Eigen::Vector3d(0.001, 0.002, -0.002) : Eigen::Vector3d::Constant(NAN);
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
    Simulation simulation(*rig.model, *rig.columns, std::vector<ToolSpec>(1), options);
    simulation.set_tool(0, tool);
    simulation.step(0);
    return simulation.ir(0);
  }
};

std::vector<TickRecord> drain(HapticChannels& channels) {
  std::vector<TickRecord> ticks;
  while (const auto t = channels.trace.pop()) ticks.push_back(*t);
  return ticks;
}

TEST(HapticLoop, OutputsTheEvaluatorsForceLimitedAndFadedWhenConfirmationsStop) {
  Fixture fixture;
  const Eigen::Vector3d pressed(0.001, 0.002, -0.002);
  const std::shared_ptr<const PreparedIR> ir = fixture.ir_for(pressed);
  const Eigen::Vector3d expected = evaluate_force(*ir, pressed, {}).force;
  ASSERT_GT(expected.norm(), 0.2);

  auto channels = std::make_unique<HapticChannels>();
  channels->tracing = true;
  const std::int64_t now = wire::monotonic_now_ns();
  channels->ir.back() = IrSlot{std::make_unique<const PreparedIR>(*ir), now};
  channels->ir.publish();
  ScriptedDevice device(parse_trajectory("units: m\nstart: [0.001, 0.002, -0.002]\nsegments: [{hold: 10}]\n", "hold"), 10);
  HapticLoopSettings settings;
  settings.force_limit = 0.2;  // below the evaluated force: clamped
  settings.max_age_s = 0.1;
  settings.fade_s = 0.05;
  settings.duration_s = 0.5;
  settings.realtime = false;
  HapticLoop loop(device, *channels, settings);
  std::atomic<bool> stop{false};
  // Confirm the IR every 10 ms for 0.2 s, then go silent (as a dead server would).
  std::thread server([&] {
    for (int i = 0; i < 20; ++i) {
      channels->confirmation.back() = {ir->ir.epoch, wire::monotonic_now_ns()};
      channels->confirmation.publish();
      std::this_thread::sleep_for(10ms);
    }
  });
  // Drain the trace while the loop runs (it holds 8192 ticks).
  std::vector<TickRecord> ticks;
  std::thread loop_thread([&] { loop.run(stop); });
  loop_thread.join();
  server.join();
  ticks = drain(*channels);
  ASSERT_GT(ticks.size(), 400u);

  const std::int64_t start = ticks.front().time_ns;
  for (const TickRecord& t : ticks) {
    const double s = static_cast<double>(t.time_ns - start) * 1e-9;
    EXPECT_EQ(t.evaluated, expected);
    EXPECT_LE(t.force.norm(), 0.2 + 1e-12);
    if (s < 0.25) {
      EXPECT_EQ(t.fade, 1.0f) << "confirmed at " << s << " s";
    }
    if (s > 0.2 + 0.1 + 0.05 + 0.02) {
      EXPECT_EQ(t.force.norm(), 0.0) << "faded out at " << s << " s";
    }
  }
  EXPECT_NEAR(ticks.front().force.norm(), 0.2, 1e-12);
  EXPECT_GT(loop.metrics().clamped, 0u);
  // Every 1 ms period of the 0.5 s run is either a tick or a skipped deadline (a loaded
  // machine skips some), so together they account for the duration.
  EXPECT_NEAR(static_cast<double>(loop.metrics().ticks + loop.metrics().missed_deadlines), 500, 25);
  EXPECT_EQ(device.last_force(), Eigen::Vector3d::Zero()) << "the loop leaves the device at zero force";
}

TEST(HapticLoop, NonFiniteInputGivesZeroForceAndAnEvent) {
  Fixture fixture;
  const std::shared_ptr<const PreparedIR> ir = fixture.ir_for(Eigen::Vector3d(0.001, 0.002, -0.002));
  auto channels = std::make_unique<HapticChannels>();
  channels->tracing = true;
  channels->ir.back() = IrSlot{std::make_unique<const PreparedIR>(*ir), wire::monotonic_now_ns()};
  channels->ir.publish();
  NanDevice device(0.1);
  HapticLoopSettings settings;
  settings.duration_s = 0.2;
  settings.realtime = false;
  settings.max_age_s = 10;
  HapticLoop loop(device, *channels, settings);
  std::atomic<bool> stop{false};
  loop.run(stop);
  int zero_after = 0;
  for (const TickRecord& t : drain(*channels)) {
    ASSERT_TRUE(t.force.allFinite());
    if (!t.own.allFinite()) {
      EXPECT_EQ(t.force, Eigen::Vector3d::Zero());
      EXPECT_TRUE(t.flags & kNonFinite);
      ++zero_after;
    }
  }
  EXPECT_GT(zero_after, 50);
}

TEST(HapticLoop, ALateTickSkipsTheMissedDeadlinesAndKeepsThePhase) {
  // A device that stalls once for 5.5 ms, like a host preempting the VM.
  class StallingDevice final : public HapticDevice {
   public:
    std::string describe() const override { return "stall"; }
    DeviceState read(double t) override {
      if (!stalled && t > 0.05) {
        stalled = true;
        std::this_thread::sleep_for(5500us);
      }
      return {};
    }
    void write_force(const Eigen::Vector3d&, double) override {}
    double force_limit() const override { return 1; }
    bool stalled = false;
  } device;
  auto channels = std::make_unique<HapticChannels>();
  channels->tracing = true;
  HapticLoopSettings settings;
  settings.duration_s = 0.2;
  settings.realtime = false;
  HapticLoop loop(device, *channels, settings);
  std::atomic<bool> stop{false};
  loop.run(stop);
  const std::vector<TickRecord> ticks = drain(*channels);
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
    std::nth_element(offsets.begin(), offsets.begin() + static_cast<std::ptrdiff_t>(offsets.size() / 2), offsets.end());
    return offsets[offsets.size() / 2];
  };
  // The stall comes at 50 ms: before it, 0-45 ms; after it, from 70 ms.
  const std::int64_t before = median_offset(0, 45'000'000), after = median_offset(70'000'000, 200'000'000);
  EXPECT_LT(std::abs(after - before), 300'000) << "median offset from the 1 ms grid: " << before << " ns before the stall, "
                                               << after << " ns after";
  EXPECT_LT(ticks.size(), 200u - 3u) << "missed ticks are skipped, not caught up";
}

}  // namespace
}  // namespace cohaptic
