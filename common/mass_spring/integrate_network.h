// One step of a mass–spring network with the thin-objects paper's backward–forward Euler
// scheme (Sec. 4.4.1), i.e. semi-implicit (symplectic) Euler:
//   a = F(x, v)/m,  v' = v + a h,  x' = x + v' h,
// with F the internal forces (internal_forces.h), the plane's normal and friction forces
// and the velocity projection of Eq. (6) (plane_friction.h), and for every driven node
// the haptic force of Eq. (5) that takes it to its commanded position
// (haptic_node_force.h). Held nodes move at their own velocity. Stable for
// omega_max h < 2 (stable_time_step.h). No allocation: the state holds its buffers.
#pragma once

#include <Eigen/Core>
#include <span>

#include "common/mass_spring/node_backing.h"
#include "common/mass_spring/mass_spring_network.h"
#include "common/mass_spring/mass_spring_state.h"

namespace cohaptic {

/// A node the tool drives this step: to `target`, with the contact normal `normal` (unit,
/// outward) that splits Eq. (5)'s force into its normal and capped tangential parts.
struct NodeDrive {
  int node = -1;
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

/// Advances `state` by h [s]. applied[i] receives the haptic force on drives[i].node [N]
/// (`applied` at least as long as `drives`). A node driven twice takes the first drive.
/// `backing` (may be null): a body behind this one pressing back on some nodes
/// (node_backing.h), over the network's node indices, solved in state.backing (prepared
/// for it by prepare_backing_solve).
void step_network(const MassSpringNetwork& network, MassSpringState& state,
                  std::span<const NodeDrive> drives, std::span<Eigen::Vector3d> applied, double h,
                  const NodeBacking* backing = nullptr) noexcept;

}  // namespace cohaptic
