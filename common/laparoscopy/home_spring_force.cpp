#include "common/laparoscopy/home_spring_force.h"

namespace cohaptic {

double home_spring_energy(const HomeSpringPatch& patch, int vertex,
                          const Eigen::Vector3d& displacement) noexcept {
  const Eigen::Vector3d rest = patch.rest_positions.col(vertex);
  const Eigen::Vector3d current = rest + displacement;
  double ring = 0;
  for (const int j : patch.ring(vertex)) {
    const Eigen::Vector3d neighbour = patch.rest_positions.col(j);
    const double stretch = (current - neighbour).norm() - (rest - neighbour).norm();
    ring += stretch * stretch;
  }
  return 0.5 * patch.home_stiffness * displacement.squaredNorm() +
         0.5 * patch.neighbour_stiffness * ring;
}

Eigen::Vector3d home_spring_load(const HomeSpringPatch& patch, int vertex,
                                 const Eigen::Vector3d& displacement) noexcept {
  const Eigen::Vector3d rest = patch.rest_positions.col(vertex);
  const Eigen::Vector3d current = rest + displacement;
  Eigen::Vector3d ring = Eigen::Vector3d::Zero();
  for (const int j : patch.ring(vertex)) {
    const Eigen::Vector3d neighbour = patch.rest_positions.col(j);
    const Eigen::Vector3d link = current - neighbour;  // L_j
    const double length = link.norm();
    if (!(length > 0)) continue;
    ring += (length - (rest - neighbour).norm()) / length * link;
  }
  return patch.home_stiffness * displacement + patch.neighbour_stiffness * ring;
}

}  // namespace cohaptic
