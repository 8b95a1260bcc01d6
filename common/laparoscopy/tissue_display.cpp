#include "common/laparoscopy/tissue_display.h"

#include <cmath>
#include <fmt/format.h>

#include "common/laparoscopy/direct_manipulation.h"
#include "common/laparoscopy/polynomial_deformation.h"
#include "common/util/error.h"

namespace cohaptic {

TissueDisplay make_tissue_display(Eigen::Matrix3Xd rest, double radius, DisplayDeformation method) {
  if (rest.cols() == 0) throw Error("tissue display: the surface has no vertex");
  for (Eigen::Index v = 0; v < rest.cols(); ++v)
    if (!rest.col(v).allFinite())
      throw Error(fmt::format("tissue display: vertex {} is not finite", v));
  if (!(radius > 0) || !std::isfinite(radius))
    throw Error(fmt::format(
        "tissue display: the radius of influence is {} m, expected positive and finite", radius));
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant(radius);
  BernsteinLattice lattice =
      identity_lattice(rest.rowwise().minCoeff() - margin, rest.rowwise().maxCoeff() + margin);
  LatticeBinding binding = bind_to_lattice(lattice, rest);
  return TissueDisplay{std::move(rest), radius, method, std::move(lattice), std::move(binding)};
}

void display_tissue(const TissueDisplay& display, const Eigen::Vector3d& contact_point,
                    const Eigen::Vector3d& tool_point, Eigen::Matrix3Xd& deformed) noexcept {
  const Eigen::Vector3d pull = tool_point - contact_point;
  if (!contact_point.allFinite() || !pull.allFinite() || pull.isZero(0)) {
    deformed = display.rest;
    return;
  }
  if (display.method == DisplayDeformation::polynomial)
    deform_polynomial(display.rest, {contact_point, tool_point, display.radius}, deformed);
  else
    deform_ffd(display.binding,
               display.lattice.control +
                   single_point_manipulation(lattice_basis(display.lattice, contact_point), pull),
               deformed);
}

}  // namespace cohaptic
