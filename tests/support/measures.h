// Small measures the tests state their expectations in: positions typed in millimetres and
// the relative error of a vector against its expected value.
#pragma once

#include <algorithm>

#include <Eigen/Core>

namespace cohaptic::testing {

/// A position given in millimetres, in metres.
inline Eigen::Vector3d mm(double x, double y, double z) { return Eigen::Vector3d(x, y, z) * 1e-3; }

/// |value − expected| / |expected| (a zero `expected` divides by 1e-300, not by zero).
inline double relative_error(const Eigen::Vector3d& value, const Eigen::Vector3d& expected) {
  return (value - expected).norm() / std::max(expected.norm(), 1e-300);
}

}  // namespace cohaptic::testing
