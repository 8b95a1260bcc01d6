#include "common/mass_spring/integrate_network.h"

#include "common/mass_spring/haptic_node_force.h"
#include "common/mass_spring/internal_forces.h"
#include "common/mass_spring/plane_friction.h"

namespace cohaptic {
namespace {

int drive_of(std::span<const NodeDrive> drives, int node) noexcept {
  for (std::size_t i = 0; i < drives.size(); ++i)
    if (drives[i].node == node) return static_cast<int>(i);
  return -1;
}

}  // namespace

void step_network(const MassSpringNetwork& network, MassSpringState& state,
                  std::span<const NodeDrive> drives, std::span<Eigen::Vector3d> applied, double h,
                  const NodeBacking* backing) noexcept {
  const MassSpringParameters& p = network.parameters;
  internal_forces(network, state.positions, state.velocities, state.forces);
  if (backing)
    add_node_backing_forces(*backing, state.backing, state.positions, state.velocities,
                            state.forces);
  for (std::size_t i = 0; i < drives.size(); ++i) applied[i].setZero();
  for (int n = 0; n < network.node_count(); ++n) {
    auto x = state.positions.col(n);
    auto v = state.velocities.col(n);
    if (network.held[static_cast<std::size_t>(n)]) {
      x += v * h;
      continue;
    }
    Eigen::Vector3d force = state.forces.col(n);
    const int drive = drives.empty() ? -1 : drive_of(drives, n);
    bool sliding = false;
    if (drive >= 0) {
      const NodeDrive& d = drives[static_cast<std::size_t>(drive)];
      const HapticNodeForce haptic =
          haptic_node_force(network.mass[n], x, v, force, d.target, d.normal, p.tool_friction, h);
      applied[static_cast<std::size_t>(drive)] = haptic.force;
      force += haptic.force;
    } else if (p.plane) {
      force += plane_reaction(*p.plane, x, v, force, network.mass[n], h, sliding);
    }
    const Eigen::Vector3d v_before = v;
    v += force * (h / network.mass[n]);
    if (p.plane && drive < 0 && height_above(*p.plane, x) <= kPlaneTouchTolerance)
      settle_on_plane(*p.plane, v_before, sliding, v);
    x += v * h;
    if (p.plane) keep_above(*p.plane, x, v);
  }
}

}  // namespace cohaptic
