// `cohaptic-lab tradeoff` on a scene whose object is a mass–spring body (the thin-objects
// paper's tube): what the sub-network a client is sent costs and what it buys.
//
// The workload (a scripted motion per scene tool) runs through the server's
// MassSpringSimulation stepped at the haptic rate: the whole network integrated with every
// tool at every tick. Its reaction on each tool is the reference: the force a user would
// feel if the server ran the whole network at the haptic rate and its force reached the
// hand at once. Each setting (free sections each side of the contact, IR rate) cuts the
// IRs from that same server, and each user's client evaluation (evaluate_force, the
// haptic loop's own function) integrates its latest IR's sub-network tick by tick. The IR
// cut after the server's step k is evaluated from tick k + 1 on, as in the networked
// system without its network delay. Costs: IR nodes and bytes per second, the client's
// µs per tick. Units as the column names say.
#pragma once

#include <string>
#include <vector>

#include "common/haptics/trajectory.h"
#include "common/scene/scene.h"

namespace cohaptic {

struct TradeoffOptions;

struct MassSpringTradeoffSetting {
  int sections =
      4;  ///< free cross-sections each side of the contact's; >= the body's: the whole network
  double ir_rate_hz = 100;
};

struct MassSpringTradeoffRow {
  MassSpringTradeoffSetting setting;
  bool whole = false;    ///< the IRs carried the whole network
  double ir_nodes = 0;   ///< mean nodes per IR
  double error_rms = 0;  ///< RMS over ticks and tools of |F - F_ref|, over the reference's peak
  double error_max = 0;  ///< max of the same, over the peak
  /// The max over the ticks where client and reference agree whether the tool touches: a
  /// contact that begins or ends a tick apart weighs a whole force.
  double error_max_same_contact = 0;
  double peak_force = 0;     ///< the reference's max |F| [N]
  double evaluation_us = 0;  ///< the client's median µs per tick and user
  double evaluation_us_p99 = 0;
  double ir_bytes_per_s = 0;  ///< to all users, per second of workload
  int irs_sent = 0;
};

/// Runs the workload (one motion per scene tool) with `setting` at the scene's haptic rate.
/// The scene's only object must be mass_spring (throws Error otherwise).
MassSpringTradeoffRow run_mass_spring_setting(const Scene& scene,
                                              const MassSpringTradeoffSetting& setting,
                                              const std::vector<Trajectory>& motions);

/// The grid: sections 1, 2, 4, 8 and the whole network, each at IR rates 10, 30, 100, 300
/// and 1000 Hz (capped at the haptic rate).
std::vector<MassSpringTradeoffSetting> mass_spring_tradeoff_grid(const Scene& scene);

/// Runs the grid; writes DIR/tradeoff.csv and DIR/tradeoff.md. Returns the exit code.
int run_mass_spring_tradeoff(const Scene& scene, const std::vector<Trajectory>& motions,
                             const TradeoffOptions& options);

}  // namespace cohaptic
