#include "common/mass_spring/internal_forces.h"

namespace cohaptic {

void internal_forces(const MassSpringNetwork& network, const Eigen::Matrix3Xd& positions,
                     const Eigen::Matrix3Xd& velocities, Eigen::Matrix3Xd& forces) noexcept {
  const MassSpringParameters& p = network.parameters;
  for (int n = 0; n < network.node_count(); ++n)
    forces.col(n) = network.mass[n] * p.gravity - p.node_damping * velocities.col(n);
  for (const Spring& spring : network.springs) {
    const Eigen::Vector3d l = positions.col(spring.b) - positions.col(spring.a);
    const double length = l.norm();
    if (!(length > 0)) continue;
    const Eigen::Vector3d direction = l / length;
    const double stretch_rate =
        (velocities.col(spring.b) - velocities.col(spring.a)).dot(direction);
    const Eigen::Vector3d on_a =
        (spring.stiffness * (length - spring.rest_length) + spring.damping * stretch_rate) *
        direction;
    forces.col(spring.a) += on_a;
    forces.col(spring.b) -= on_a;
  }
}

double potential_energy(const MassSpringNetwork& network, const Eigen::Matrix3Xd& positions) {
  double energy = 0;
  for (const Spring& spring : network.springs) {
    const double stretch =
        (positions.col(spring.b) - positions.col(spring.a)).norm() - spring.rest_length;
    energy += 0.5 * spring.stiffness * stretch * stretch;
  }
  for (int n = 0; n < network.node_count(); ++n)
    energy -= network.mass[n] * network.parameters.gravity.dot(positions.col(n));
  return energy;
}

double kinetic_energy(const MassSpringNetwork& network, const Eigen::Matrix3Xd& velocities) {
  double energy = 0;
  for (int n = 0; n < network.node_count(); ++n)
    energy += 0.5 * network.mass[n] * velocities.col(n).squaredNorm();
  return energy;
}

}  // namespace cohaptic
