// Temperature-dependent stiffness (the thin-objects paper, Sec. 4.5, after Terzopoulos):
//   k_c(theta) = k_c(theta0) - nu_c (theta - theta0),
//   nu_c = c alpha_L E sum Vol(T_c)/|l_c|^2                                     (Eq. 7)
// Since Eq. (1) gives k_c(theta0) = E sum Vol(T_c)/|l_c|^2, nu_c = c alpha_L k_c(theta0): a
// heated spring's stiffness, and with Eq. (2) its damping, scale by the one factor
//   1 - c alpha_L (theta - theta0),
// the same for every spring at the same temperature rise. A spring is heated when both its
// ends lie in the region's box (at rest). Units: K, 1/K, m.
#pragma once

#include <Eigen/Core>

#include "common/mass_spring/mass_spring_network.h"

namespace cohaptic {

struct HeatedRegion {
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero(), box_max = Eigen::Vector3d::Zero();  ///< [m]
  double temperature_rise = 0;       ///< theta - theta0 [K]
  double expansion_coefficient = 0;  ///< alpha_L [1/K]
  double coupling = 1;               ///< c, the positive constant of Eq. (7)
};

/// 1 - c alpha_L (theta - theta0); Error unless it is in (0, 1] for a rise >= 0 (a
/// spring cannot lose all its stiffness and stay a spring).
double thermal_stiffness_factor(const HeatedRegion& region);

/// Scales the stiffness and damping of the springs inside `region`; returns how many.
int heat_springs(MassSpringNetwork& network, const HeatedRegion& region);

}  // namespace cohaptic
