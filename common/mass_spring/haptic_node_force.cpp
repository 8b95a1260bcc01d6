#include "common/mass_spring/haptic_node_force.h"

namespace cohaptic {

HapticNodeForce haptic_node_force(double mass, const Eigen::Vector3d& x, const Eigen::Vector3d& v,
                                  const Eigen::Vector3d& other_forces,
                                  const Eigen::Vector3d& target, const Eigen::Vector3d& normal,
                                  double tool_friction, double h) noexcept {
  HapticNodeForce result;
  result.force = mass * ((target - x) / h - v) / h - other_forces;
  const double normal_part = result.force.dot(normal);
  const Eigen::Vector3d tangential = result.force - normal_part * normal;
  const double limit = tool_friction * std::abs(normal_part);
  const double size = tangential.norm();
  if (size > limit) {
    result.force = normal_part * normal + (size > 0 ? Eigen::Vector3d(tangential * (limit / size))
                                                    : Eigen::Vector3d::Zero());
    result.slipped = true;
  }
  return result;
}

}  // namespace cohaptic
