// The laparoscopy paper's local deformation for display (its Eq. 1): every surface vertex
// within the radius of influence R of the collision point P moves along AP (A the tool
// point), by the second-order profile
//   depth(r) = a0 + a2 r^2,  a0 = |AP|,  a2 = -|AP| / R^2,
// with r the vertex's rest distance to P: P itself goes to A, the rim at r = R stays, and
// nothing beyond R moves. For the probe P and A follow the tool every tick; for grasping
// forceps P is the grasp point, fixed until release. Force is computed apart (Eq. 8).
// noexcept, allocation-free; units: m.
#pragma once

#include <Eigen/Core>

namespace cohaptic {

struct PolynomialDent {
  Eigen::Vector3d contact_point;  ///< P on the rest surface [m]
  Eigen::Vector3d tool_point;     ///< A, where P is moved to [m]
  double radius = 0;              ///< radius of influence R [m], > 0
};

/// depth(r) / |AP| = 1 - r^2 / R^2 within R, 0 beyond (and 0 when R is not positive).
double polynomial_depth_fraction(double r, double radius) noexcept;

/// deformed = rest moved by the dent (same size as rest; the caller sizes it once).
void deform_polynomial(const Eigen::Matrix3Xd& rest, const PolynomialDent& dent,
                       Eigen::Matrix3Xd& deformed) noexcept;

}  // namespace cohaptic
