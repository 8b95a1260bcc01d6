#include "common/mass_spring/stable_time_step.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cohaptic {

namespace {

// The largest eigenvalue of M^-1/2 A M^-1/2 for A = sum over springs of a_s n n^T (a_s the
// spring's `coefficient`, n its unit direction at rest), held nodes removed: power iteration.
template <typename Coefficient>
double largest_spring_eigenvalue(const MassSpringNetwork& network, Coefficient coefficient) {
  const int nodes = network.node_count();
  Eigen::VectorXd inverse_root_mass(nodes);
  for (int n = 0; n < nodes; ++n)
    inverse_root_mass[n] =
        network.held[static_cast<std::size_t>(n)] ? 0 : 1 / std::sqrt(network.mass[n]);
  auto apply = [&](const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& y) {
    y.setZero();
    for (const Spring& spring : network.springs) {
      Eigen::Vector3d n =
          network.rest_positions.col(spring.b) - network.rest_positions.col(spring.a);
      const double length = n.norm();
      if (!(length > 0)) continue;
      n /= length;
      const double wa = inverse_root_mass[spring.a], wb = inverse_root_mass[spring.b];
      const double stretch =
          n.dot(wb * x.col(spring.b) - wa * x.col(spring.a)) * coefficient(spring);
      y.col(spring.a) -= wa * stretch * n;
      y.col(spring.b) += wb * stretch * n;
    }
  };
  Eigen::Matrix3Xd x(3, nodes), y(3, nodes);
  for (int n = 0; n < nodes; ++n)
    x.col(n) =
        Eigen::Vector3d(1 + 0.37 * n, 0.5 - 0.21 * n, ((n % 3) - 1.0)) * inverse_root_mass[n];
  double lambda = 0;
  for (int iteration = 0; iteration < 2000; ++iteration) {
    const double size = x.norm();
    if (!(size > 0)) return 0;
    x /= size;
    apply(x, y);
    const double next = x.cwiseProduct(y).sum();  // Rayleigh quotient, from below
    const bool converged = iteration > 20 && std::abs(next - lambda) <= 1e-10 * next;
    lambda = next;
    x = y;
    if (converged) break;
  }
  return lambda > 0 ? lambda : 0;
}

}  // namespace

double critical_time_step(const MassSpringNetwork& network) {
  const double omega_squared =
      largest_spring_eigenvalue(network, [](const Spring& s) { return s.stiffness; });
  if (!(omega_squared > 0)) return std::numeric_limits<double>::infinity();
  double lightest = std::numeric_limits<double>::infinity();
  for (int n = 0; n < network.node_count(); ++n)
    if (!network.held[static_cast<std::size_t>(n)]) lightest = std::min(lightest, network.mass[n]);
  const double damping_rate =
      largest_spring_eigenvalue(network, [](const Spring& s) { return s.damping; }) +
      network.parameters.node_damping / lightest;
  const double omega = std::sqrt(omega_squared), xi = damping_rate / (2 * omega);
  return 2 / omega * (std::sqrt(1 + xi * xi) - xi);
}

}  // namespace cohaptic
