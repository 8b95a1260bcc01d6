// Tools pressing a mass–spring network (the thin-objects paper, Sec. 4.3), advanced over
// one period: the function the server runs on the whole body with every user's tool and
// the client runs on its sub-network at the haptic rate (the IR's evaluation).
//
// At the start of the period each tool is tested against the surface (surface_collision.h).
// A colliding tool drives its contact node s_n by the displacement
//   d = -N_s depth + (tangential part of the tool's motion since the previous period),
// i.e. the node follows the tool: into the surface as far as the tool penetrates, along it
// as the tool slides (the tangential part limited by the tool's friction through Eq. 5).
// The period is split into n = ceil(period / time_step) integrator steps; the node's
// target moves by d/n per step, and the tool feels minus the mean Eq. (5) force.
// A tool that does not collide forgets its previous position. Two tools on one node: the
// first drives it, the second feels nothing. No allocation, no exception.
#pragma once

#include <Eigen/Core>
#include <array>
#include <span>

#include "common/mass_spring/integrate_network.h"
#include "common/mass_spring/mass_spring_network.h"
#include "common/mass_spring/mass_spring_state.h"

namespace cohaptic {

/// Tools one advance handles; more are ignored.
inline constexpr int kMaxNetworkTools = 8;

/// What a tool carries from one period to the next.
struct ToolPress {
  bool pressing = false;                               ///< collided in the previous period
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();  ///< its position then [m]
};

struct ToolOnNetwork {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< [m]; non-finite: absent
  double radius = 0;                                   ///< [m]
};

struct NetworkToolReaction {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< on the tool [N]
  bool colliding = false;
  int node = -1;     ///< the driven node
  double depth = 0;  ///< at the start of the period [m]
};

/// Advances `state` by `period` [s] (> 0) with `tools` pressing; presses[i] and reactions[i]
/// belong to tools[i] (both at least as long as tools; at most kMaxNetworkTools used).
/// `backing` (may be null) presses back on the network every substep (step_network).
void advance_with_tools(const MassSpringNetwork& network, MassSpringState& state,
                        std::span<const ToolOnNetwork> tools, std::span<ToolPress> presses,
                        std::span<NetworkToolReaction> reactions, double period,
                        const NodeBacking* backing = nullptr) noexcept;

/// The number of integrator steps for `period`.
int substeps_for(const MassSpringNetwork& network, double period) noexcept;

}  // namespace cohaptic
