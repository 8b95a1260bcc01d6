#include "common/mass_spring/network_equilibrium.h"

#include <Eigen/LU>
#include <fmt/format.h>

#include "common/mass_spring/network_stiffness.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

// The springs' forces on every dof (no dampers: the network at rest).
void spring_forces(const MassSpringNetwork& network, const Eigen::Matrix3Xd& x,
                   Eigen::VectorXd& force) {
  force.setZero();
  for (const Spring& s : network.springs) {
    const Eigen::Vector3d l = x.col(s.b) - x.col(s.a);
    const double length = l.norm();
    if (!(length > 0)) continue;
    const Eigen::Vector3d on_a = s.stiffness * (length - s.rest_length) * (l / length);
    force.segment<3>(3 * s.a) += on_a;
    force.segment<3>(3 * s.b) -= on_a;
  }
}

}  // namespace

NetworkEquilibrium network_equilibrium(const MassSpringNetwork& network,
                                       std::span<const PrescribedDisplacement> prescribed,
                                       const Eigen::Matrix3Xd& start, double tolerance) {
  const int dofs = 3 * network.node_count();
  std::vector<bool> set(static_cast<std::size_t>(dofs), false);
  NetworkEquilibrium result;
  result.positions = start;
  for (int n = 0; n < network.node_count(); ++n)
    if (network.held[static_cast<std::size_t>(n)]) {
      result.positions.col(n) = network.rest_positions.col(n);
      for (int a = 0; a < 3; ++a) set[static_cast<std::size_t>(3 * n + a)] = true;
    }
  for (const PrescribedDisplacement& p : prescribed) {
    result.positions(p.dof % 3, p.dof / 3) = network.rest_positions(p.dof % 3, p.dof / 3) + p.value;
    set[static_cast<std::size_t>(p.dof)] = true;
  }
  std::vector<int> free;
  for (int d = 0; d < dofs; ++d)
    if (!set[static_cast<std::size_t>(d)]) free.push_back(d);
  const auto count = static_cast<Eigen::Index>(free.size());

  Eigen::VectorXd force(dofs);
  for (;; ++result.iterations) {
    spring_forces(network, result.positions, force);
    const Eigen::MatrixXd tangent = network_stiffness(result.positions, network.springs).toDense();
    Eigen::VectorXd residual(count);
    Eigen::MatrixXd k(count, count);
    for (Eigen::Index i = 0; i < count; ++i) {
      residual[i] = force[free[static_cast<std::size_t>(i)]];
      for (Eigen::Index j = 0; j < count; ++j)
        k(i, j) = tangent(free[static_cast<std::size_t>(i)], free[static_cast<std::size_t>(j)]);
    }
    if (count == 0 || residual.cwiseAbs().maxCoeff() <= tolerance) break;
    if (result.iterations == 50)  // Newton converges in a few from a nearby equilibrium
      throw Error(
          fmt::format("network equilibrium: Newton left a free force of {} N after 50 iterations",
                      residual.cwiseAbs().maxCoeff()));
    const Eigen::VectorXd step = k.partialPivLu().solve(residual);
    for (Eigen::Index i = 0; i < count; ++i) {
      const int d = free[static_cast<std::size_t>(i)];
      result.positions(d % 3, d / 3) += step[i];
    }
  }
  result.reaction = Eigen::VectorXd::Zero(dofs);
  for (const PrescribedDisplacement& p : prescribed) result.reaction[p.dof] = -force[p.dof];
  return result;
}

}  // namespace cohaptic
