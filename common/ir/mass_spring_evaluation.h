// Preparing and evaluating a mass–spring IR body (mass_spring_ir.h): the client's side of
// the thin-objects paper's model. prepare_mass_spring (off the haptic thread) checks the
// sub-network and indexes its surface; make_mass_spring_state copies the server's state
// into a fresh evaluation state; advance_mass_spring (on the haptic thread: noexcept, no
// allocation) integrates the sub-network over one haptic period dt with the own tool
// (tool 0) and the remote tools pressing it (tool_coupling.h), and returns the own tool's
// reaction. Units: SI.
#pragma once

#include <Eigen/Core>
#include <array>
#include <span>

#include "common/ir/mass_spring_ir.h"
#include "common/mass_spring/mass_spring_network.h"
#include "common/mass_spring/mass_spring_state.h"
#include "common/mass_spring/tool_coupling.h"

namespace cohaptic {

struct PreparedMassSpring {
  MassSpringNetwork
      network;  ///< the IR's sub-network, checked and indexed; rest_positions = the IR's positions
};

/// What a mass–spring body's evaluation changes from tick to tick.
struct MassSpringPatchState {
  MassSpringState network;
  std::array<ToolPress, kMaxNetworkTools> presses{};
};

/// Throws Error naming the problem (sizes, indices, signs, too many remote tools).
PreparedMassSpring prepare_mass_spring(const MassSpringIr& ir);

MassSpringPatchState make_mass_spring_state(const MassSpringIr& ir,
                                            const PreparedMassSpring& prepared);

/// Advances `state` by dt [s] with the tools at `own_tool` (radius own_radius) and
/// remote_tools[i] (radius ir.remote_radii[i]; NaN: absent); the own tool's reaction.
/// dt <= 0 or not finite: nothing moves and the reaction is zero.
NetworkToolReaction advance_mass_spring(const MassSpringIr& ir, const PreparedMassSpring& prepared,
                                        MassSpringPatchState& state,
                                        const Eigen::Vector3d& own_tool, double own_radius,
                                        std::span<const Eigen::Vector3d> remote_tools,
                                        double dt) noexcept;

}  // namespace cohaptic
