// MassSpringState: the mutable state of a mass–spring network (mass_spring_network.h):
// node positions and velocities, and the force buffer the integrator fills each step (kept
// here so that a step allocates nothing). Sized once for its network by make_state; the
// backing's workspace is sized for a backing by prepare_backing_solve (node_backing.h).
// Units: m, m/s, N.
#pragma once

#include <Eigen/Core>

#include "common/mass_spring/mass_spring_network.h"
#include "common/mass_spring/node_backing.h"

namespace cohaptic {

struct MassSpringState {
  Eigen::Matrix3Xd positions;   ///< x [m]
  Eigen::Matrix3Xd velocities;  ///< v [m/s]
  Eigen::Matrix3Xd forces;      ///< scratch: the forces of the current step [N]
  NodeBackingSolve backing;     ///< the backing's pushes and workspace (empty: no backing)
};

/// The network at rest: positions at rest_positions, velocities zero.
MassSpringState make_state(const MassSpringNetwork& network);

}  // namespace cohaptic
