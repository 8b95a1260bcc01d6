// The static equilibrium of a mass-spring network's springs, geometrically nonlinear: the
// positions where every spring force f = k (|l| - l0) l/|l| balances at each node that is
// neither held nor prescribed, found by Newton's method on the springs' tangent stiffness
// (network_stiffness.h at the current positions).
// No gravity, dampers or masses: the slow limit of the network's dynamics, and the
// reference a push in time tends to as it slows (the linearised one, the tangent at rest,
// holds only while the springs barely turn). Dense: for small networks (a few hundred
// nodes). Units: m, N.
#pragma once

#include <Eigen/Core>
#include <span>

#include "common/fem/static_solve.h"
#include "common/mass_spring/mass_spring_network.h"

namespace cohaptic {

struct NetworkEquilibrium {
  Eigen::Matrix3Xd positions;  ///< [m]
  Eigen::VectorXd
      reaction;  ///< the force holding each prescribed dof, 3 per node (0 elsewhere) [N]
  int iterations = 0;
};

/// Equilibrium with `prescribed` dofs displaced from rest (network.held nodes stay at rest),
/// starting Newton from `start` (e.g. a nearby equilibrium). Throws Error if Newton does not
/// bring the free forces below `tolerance` [N] in 50 iterations.
NetworkEquilibrium network_equilibrium(const MassSpringNetwork& network,
                                       std::span<const PrescribedDisplacement> prescribed,
                                       const Eigen::Matrix3Xd& start, double tolerance = 1e-10);

}  // namespace cohaptic
