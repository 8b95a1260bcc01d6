// The largest stable step of the semi-implicit Euler integrator for a network at rest:
// h_crit = 2 / omega_max, with omega_max^2 the largest eigenvalue of M^-1 K for the
// stiffness K = sum over springs of k n n^T (n the spring's unit direction at rest),
// found by power iteration on the symmetric M^-1/2 K M^-1/2. Held nodes do not count.
// (For one mass on a spring to a held node, h_crit = 2 sqrt(m/k).) Damping shortens it:
// for x'' = -omega^2 x - c x' the scheme is stable while h^2 omega^2 + 2 h c < 4, i.e.
//   h_crit = (2/omega) (sqrt(1 + xi^2) - xi),  xi = c / (2 omega),
// taken here with omega_max and the largest damping rate c_max = (largest eigenvalue of
// M^-1/2 C M^-1/2 for the springs' damping C) + beta / m_min: a bound on the safe side
// (it is exact for one mass on one spring). Units: s.
#pragma once

#include "common/mass_spring/mass_spring_network.h"

namespace cohaptic {

/// 2 / omega_max [s]; infinity for a network without springs between free nodes.
double critical_time_step(const MassSpringNetwork& network);

/// The step a scene gets by default: this fraction of the critical step.
inline constexpr double kDefaultStepFraction = 0.8;

}  // namespace cohaptic
