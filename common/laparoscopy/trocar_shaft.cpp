#include "common/laparoscopy/trocar_shaft.h"

#include <Eigen/Geometry>
#include <cmath>

namespace cohaptic {

std::optional<ShaftFrame> shaft_frame(const Eigen::Vector3d& pivot, const Eigen::Vector3d& tool,
                                      const Eigen::Vector3d& opening_hint) noexcept {
  const Eigen::Vector3d along = tool - pivot;
  const double length = along.norm();
  if (!(length > 0) || !std::isfinite(length)) return std::nullopt;
  const Eigen::Vector3d axis = along / length;
  Eigen::Vector3d opening = opening_hint - opening_hint.dot(axis) * axis;
  const double norm = opening.norm();
  // Below this the hint is (nearly) along the shaft and its projection mostly rounding.
  constexpr double kParallel = 1e-9;
  if (opening_hint.allFinite() && norm > kParallel * opening_hint.norm() && norm > 0)
    opening /= norm;
  else
    opening = axis.unitOrthogonal();
  return ShaftFrame{pivot, tool, axis, opening};
}

}  // namespace cohaptic
