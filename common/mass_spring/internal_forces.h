// The forces on every node of a mass–spring network except the plane's (the thin-objects
// paper, Sec. 4.4.1): F_j = sum_i F_ij^s + m_j g - beta v_j, with the spring–damper force
//   F_ij^s = [k_ij (|l| - l0_ij) + k^d_ij (dl/dt . l/|l|)] l/|l|,   l = x_i - x_j,
// i.e. a stretched spring pulls its ends together and the damper resists the rate of
// stretch. (The paper writes the damper term with a minus sign and l unnormalised; with
// l = x_i - x_j the sign that damps is +, and the unit direction keeps k^d in N s/m.)
// A spring of zero length contributes nothing (no direction). Units: N. No allocation.
#pragma once

#include <Eigen/Core>

#include "common/mass_spring/mass_spring_network.h"

namespace cohaptic {

/// Overwrites `forces` (3 x node count) with the internal, gravity and damping forces.
void internal_forces(const MassSpringNetwork& network, const Eigen::Matrix3Xd& positions,
                     const Eigen::Matrix3Xd& velocities, Eigen::Matrix3Xd& forces) noexcept;

/// The potential energy of the springs and of gravity (gravity's zero at the origin) [J].
double potential_energy(const MassSpringNetwork& network, const Eigen::Matrix3Xd& positions);
/// The kinetic energy [J].
double kinetic_energy(const MassSpringNetwork& network, const Eigen::Matrix3Xd& velocities);

}  // namespace cohaptic
