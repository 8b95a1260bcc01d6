#include "common/laparoscopy/polynomial_deformation.h"

namespace cohaptic {
namespace {

/// 1 - r^2 / R^2 from the squares (no square root per vertex); 0 from the rim outwards.
double fraction_of_squares(double r2, double radius2) noexcept {
  if (!(radius2 > 0) || !(r2 < radius2)) return 0;
  return 1 - r2 / radius2;
}

}  // namespace

double polynomial_depth_fraction(double r, double radius) noexcept {
  if (!(radius > 0) || !(r >= 0)) return 0;
  return fraction_of_squares(r * r, radius * radius);
}

void deform_polynomial(const Eigen::Matrix3Xd& rest, const PolynomialDent& dent,
                       Eigen::Matrix3Xd& deformed) noexcept {
  const Eigen::Vector3d push = dent.tool_point - dent.contact_point;  // |push| = a0, along AP
  const double radius2 = dent.radius > 0 ? dent.radius * dent.radius : 0;
  for (Eigen::Index v = 0; v < rest.cols(); ++v)
    deformed.col(v) =
        rest.col(v) +
        fraction_of_squares((rest.col(v) - dent.contact_point).squaredNorm(), radius2) * push;
}

}  // namespace cohaptic
