// `cohaptic-lab stability`: where haptic rendering stays stable, and what the
// stabilising option costs.
//
// The closed loop of one haptic client, in process and in model time: the hand model
// (common/haptics/hand_model.h) presses a virtual wall (the plane z = 0, solid below) of
// stiffness K, 10 mm deep at 10 mm/s, holds 1.5 s and comes back. Each haptic tick (period
// T) outputs the wall's force, zero-order held, computed from the tool position of an
// earlier moment:
//   - shift delay tau: the position tau ago (a network round trip, as under P0);
//   - step delay T_s: the environment takes a position at the start of each step of length
//     T_s and answers at its end (a slow simulation): the position is up to 2 T_s old and
//     the force changes only every T_s.
// Positions exist only at ticks: a delay that is not a whole number of ticks uses the
// latest tick at or before the moment (at 500 Hz, tau = 5 ms acts as 6 ms; the bound uses
// 5 ms). With the passivity controller (common/haptics/passivity_controller.h) the output is
// filtered, and limited inside it.
// A run is passive when the energy the wall gave the hand is at most 1 mJ (a sampled spring
// leaks a few µJ; an unstable loop gives tenths of a joule), and oscillating when a force
// oscillation episode (common/study/measures.h) is still going in the last 0.5 s of the
// hold. Stable = passive and not oscillating.
//
// The sampled-data passivity bound (Colgate and Schenkel 1997) for a wall against a device
// with damping b is K < 2 b / T; with a latency tau it becomes, to first order,
// K < b / (T / 2 + tau). Here b is the hand's damping (the hand model's c).
// Units: N/m, Hz, s, J.
#pragma once

#include <filesystem>
#include <vector>

#include "common/haptics/hand_model.h"
#include "common/study/force_trace.h"
#include "lab/lab_command.h"

namespace cohaptic {

struct WallLoopSettings {
  double stiffness_n_per_m = 1000;
  double haptic_rate_hz = 1000;
  double shift_delay_s = 0;
  double step_period_s = 0;  ///< 0: the force follows every tick
  bool passivity_control = false;
  HandParameters hand;
  double force_limit_n = 3.3;
};

struct WallLoopResult {
  ForceTrace trace;
  double energy_given_to_hand_j = 0;
  bool oscillating = false;  ///< an oscillation episode in the last 0.5 s of the hold
  double peak_force_n = 0;
  long controller_ticks = 0;  ///< ticks on which the passivity controller acted
  double dissipated_j = 0;    ///< energy its damping took out

  bool passive() const { return energy_given_to_hand_j <= 1e-3; }
  bool stable() const { return passive() && !oscillating; }
};

WallLoopResult run_wall_loop(const WallLoopSettings& settings);

/// First-order passivity bound on K for `settings` [N/m]: b / (T_hold / 2 + latency), with
/// T_hold = max(T, T_s) and latency = tau + T_s (T_s = 0 without step delay).
double passivity_bound(const WallLoopSettings& settings);

struct StabilityOptions {
  std::filesystem::path out;
  HandParameters hand;
};

/// Runs the map (stiffness x haptic rate x shift delay, and x step delay), with and without
/// the passivity controller; writes DIR/stability.csv, DIR/stability.md, DIR/stability.svg.
int run_stability(const StabilityOptions& options);

/// `cohaptic-lab stability --out DIR [--hand-mass KG ...]`.
LabCommand add_stability_command(CLI::App& lab);

}  // namespace cohaptic
