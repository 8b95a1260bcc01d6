// Stability of haptic rendering: the passivity controller on its own, the wall loop's
// boundary against the sampled-data passivity bound (theory), the controller turning a
// diverging configuration passive, and the controller inside the client's haptic loop.
#include <gtest/gtest.h>

#include <cmath>

#include "client/haptic_loop.h"
#include "common/haptics/passivity_controller.h"
#include "common/haptics/scripted_device.h"
#include "common/study/measures.h"
#include "lab/stability.h"
#include "proto/wire/header.h"
#include "support/driven_clock.h"

namespace cohaptic {
namespace {

TEST(PassivityController, LeavesAPassiveSpringUntouched) {
  // A 2000 N/m wall sampled at 1 kHz, the tool moving 2 mm in and out once (no delay).
  PassivityController controller;
  double work_on_hand = 0;
  Eigen::Vector3d last_x = Eigen::Vector3d::Zero(), last_f = Eigen::Vector3d::Zero();
  for (int k = 0; k <= 1000; ++k) {
    const double t = k * 1e-3;
    const Eigen::Vector3d x(0, 0, -0.002 * std::sin(M_PI * t));
    const Eigen::Vector3d wall(0, 0, 2000 * std::max(0.0, -x.z()));
    const Eigen::Vector3d out = controller.filter(t, x, wall);
    EXPECT_EQ(out, wall) << "t " << t;
    work_on_hand += last_f.dot(x - last_x);
    last_x = x;
    last_f = out;
  }
  EXPECT_EQ(controller.active_ticks(), 0);
  // The zero-order hold gives the hand a little (the observer books the same): under the
  // tolerance, so nothing is damped.
  EXPECT_GT(work_on_hand, 0.0);
  EXPECT_NEAR(controller.observed_energy(), -work_on_hand, 1e-12);
  EXPECT_LT(work_on_hand, 1e-4);
}

TEST(PassivityController, BoundsWhatAnActiveEnvironmentGivesTheHand) {
  // An environment that pushes the tool along its motion (negative damping, -20 N s/m),
  // the tool at a constant 10 mm/s: without the controller the hand gains F v t.
  PassivityController controller;
  double work_on_hand = 0;
  Eigen::Vector3d last_x = Eigen::Vector3d::Zero(), last_f = Eigen::Vector3d::Zero();
  const Eigen::Vector3d velocity(0.01, 0, 0);
  for (int k = 0; k <= 2000; ++k) {
    const double t = k * 1e-3;
    const Eigen::Vector3d x = velocity * t;
    const Eigen::Vector3d out = controller.filter(t, x, 20 * velocity);
    work_on_hand += last_f.dot(x - last_x);
    last_x = x;
    last_f = out;
  }
  const double uncontrolled = 20 * velocity.squaredNorm() * 2.0;  // 4 mJ over 2 s
  EXPECT_LT(work_on_hand, 1e-4 + 1e-5)
      << "at most the tolerance and one tick's work; uncontrolled " << uncontrolled;
  EXPECT_GT(controller.active_ticks(), 1000);
  EXPECT_GT(controller.dissipated_energy(), 0.9 * uncontrolled);
}

TEST(PassivityController, LimitsItsOwnOutputAndBooksWhatTheDeviceReceived) {
  // A 1 N limit against an environment pushing 3 N along a steady 10 mm/s motion: every
  // output is within the limit, and the energy observed is the work the limited output did.
  PassivityController controller(0.2, 1.0);
  double work_on_hand = 0;
  Eigen::Vector3d last_x = Eigen::Vector3d::Zero(), last_f = Eigen::Vector3d::Zero();
  for (int k = 0; k <= 500; ++k) {
    const double t = k * 1e-3;
    const Eigen::Vector3d x(0.01 * t, 0, 0);
    const Eigen::Vector3d out = controller.filter(t, x, Eigen::Vector3d(3, 0, 0));
    EXPECT_LE(out.norm(), 1.0 + 1e-12);
    work_on_hand += last_f.dot(x - last_x);
    last_x = x;
    last_f = out;
  }
  EXPECT_NEAR(controller.observed_energy(), -work_on_hand, 1e-12);
  EXPECT_LE(work_on_hand, 1e-4 + 1e-5 + 1e-12) << "the tolerance and one tick's work (1 N x 10 um)";
  EXPECT_GT(controller.active_ticks(), 0);
}

TEST(WallLoop, StaysStableBelowTheSampledDataBoundAndNotAboveIt) {
  // Colgate and Schenkel: against damping b a wall sampled with period T is passive for
  // K < 2 b / T. The hand's b is 8 N s/m: 16,000 N/m at 1 kHz, 8,000 N/m at 500 Hz.
  for (const double rate : {500.0, 1000.0}) {
    WallLoopSettings settings;
    settings.haptic_rate_hz = rate;
    const double bound = passivity_bound(settings);
    EXPECT_NEAR(bound, 2 * 8.0 * rate, 1e-9);
    settings.stiffness_n_per_m = 0.5 * bound;
    const WallLoopResult below = run_wall_loop(settings);
    EXPECT_TRUE(below.stable()) << rate << " Hz: energy " << below.energy_given_to_hand_j;
    EXPECT_GT(below.peak_force_n, 2.5) << "it did press";
    settings.stiffness_n_per_m = 2 * bound;
    const WallLoopResult above = run_wall_loop(settings);
    EXPECT_FALSE(above.passive()) << rate << " Hz: energy " << above.energy_given_to_hand_j;
    EXPECT_GT(above.energy_given_to_hand_j, 100 * below.energy_given_to_hand_j);
  }
  // A shift delay lowers the bound: 2,000 N/m is stable without delay, not with 10 ms.
  WallLoopSettings delayed;
  delayed.stiffness_n_per_m = 2000;
  EXPECT_TRUE(run_wall_loop(delayed).stable());
  delayed.shift_delay_s = 0.010;
  EXPECT_LT(passivity_bound(delayed), 2000);
  EXPECT_FALSE(run_wall_loop(delayed).stable());
}

TEST(WallLoop, ThePassivityControllerTurnsADivergingLoopPassiveAndCostsNothingWhenAllIsWell) {
  WallLoopSettings settings;
  settings.stiffness_n_per_m = 32000;  // twice the bound at 1 kHz
  const WallLoopResult plain = run_wall_loop(settings);
  settings.passivity_control = true;
  const WallLoopResult controlled = run_wall_loop(settings);
  EXPECT_FALSE(plain.passive());
  EXPECT_TRUE(controlled.passive()) << controlled.energy_given_to_hand_j;
  EXPECT_GT(controlled.controller_ticks, 0);
  EXPECT_GT(controlled.dissipated_j, 0.0);

  WallLoopSettings calm;
  calm.stiffness_n_per_m = 4000;
  const WallLoopResult calm_plain = run_wall_loop(calm);
  calm.passivity_control = true;
  const WallLoopResult calm_controlled = run_wall_loop(calm);
  EXPECT_EQ(calm_controlled.controller_ticks, 0);
  EXPECT_EQ(calm_controlled.trace.force, calm_plain.trace.force);
}

TEST(HapticLoop, PassivityControlStopsAnActiveForceFromFeedingTheHand) {
  // P0: the server's force pushes along the tool's steady motion (as a delayed force on
  // release does). The work it does on the moving tool grows without the controller and
  // stays at the controller's tolerance with it. The loop runs on a driven clock: on the
  // real one, a stalled tick moves the tool a long step under the force before the
  // controller can answer, and the work it books then depends on the machine's load.
  const auto work_done = [](bool passivity_control) {
    testing::DrivenClock clock;
    auto channels = std::make_unique<HapticChannels>();
    channels->tracing = true;
    channels->force.back() = ForceSlot{Eigen::Vector3d(0.5, 0, 0), clock.now, 1, true};
    channels->force.publish();
    ScriptedDevice device(
        Trajectory({0.0, 1.0}, {Eigen::Vector3d::Zero(), Eigen::Vector3d(0.02, 0, 0)}, "slide"),
        3.3);
    HapticLoopSettings settings;
    settings.protocol = HapticProtocol::p0;
    settings.duration_s = 0.6;
    settings.realtime = false;
    settings.max_age_s = 10;
    settings.passivity_control = passivity_control;
    HapticLoop loop(device, *channels, settings, clock.haptic());
    std::atomic<bool> stop{false};
    loop.run(stop);
    ForceTrace trace;
    while (const auto tick = channels->trace.pop()) {
      trace.time_s.push_back(static_cast<double>(tick->time_ns) * 1e-9);
      trace.force.push_back(tick->force);
      trace.position.push_back(tick->own);
    }
    EXPECT_GT(trace.size(), 300u);
    return std::make_pair(energy_given_to_hand(trace), loop.passivity().active_ticks());
  };
  const auto [plain, plain_ticks] = work_done(false);
  const auto [controlled, controlled_ticks] = work_done(true);
  EXPECT_GT(plain, 0.004) << "0.5 N over about 12 mm";
  EXPECT_EQ(plain_ticks, 0);
  EXPECT_LT(controlled, 2e-4);
  EXPECT_GT(controlled_ticks, 100);
}

}  // namespace
}  // namespace cohaptic
