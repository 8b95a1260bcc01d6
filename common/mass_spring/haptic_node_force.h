// The haptic force of the thin-objects paper, Eq. (5): the force F^h the tool must apply to
// the contact node c so that one semi-implicit Euler step of length h takes it from x to
// the commanded position x*, given every other force F on it:
//   F^h = m ((x* - x)/h - v)/h - F.
// Its tangential part (w.r.t. the contact normal N) is capped by the tool's friction:
// |F^h_t| <= mu |F^h . N|; when capped the node lands short of x* tangentially (the tool
// slips over the surface). The caller integrates the node with F + F^h: uncapped, it lands
// exactly on x*. Units: N, m, kg, s.
#pragma once

#include <Eigen/Core>

namespace cohaptic {

struct HapticNodeForce {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< F^h on the node [N]
  bool slipped = false;                             ///< the friction cap applied
};

HapticNodeForce haptic_node_force(double mass, const Eigen::Vector3d& x, const Eigen::Vector3d& v,
                                  const Eigen::Vector3d& other_forces,
                                  const Eigen::Vector3d& target, const Eigen::Vector3d& normal,
                                  double tool_friction, double h) noexcept;

}  // namespace cohaptic
