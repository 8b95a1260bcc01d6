#include "common/fem/linear_elastic_material.h"

#include <cmath>
#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {

void validate(const LinearElasticMaterial& material) {
  if (!std::isfinite(material.youngs_modulus) || material.youngs_modulus <= 0)
    throw Error(fmt::format("Young's modulus must be a positive number of pascals, got {}",
                            material.youngs_modulus));
  if (!std::isfinite(material.poisson_ratio) || material.poisson_ratio <= -1 ||
      material.poisson_ratio >= 0.5)
    throw Error(
        fmt::format("Poisson's ratio must lie in (-1, 0.5), got {}", material.poisson_ratio));
}

Eigen::Matrix<double, 6, 6> elasticity_matrix(const LinearElasticMaterial& material) {
  const double lambda = material.lame_lambda();
  const double mu = material.shear_modulus();
  Eigen::Matrix<double, 6, 6> d = Eigen::Matrix<double, 6, 6>::Zero();
  d.topLeftCorner<3, 3>().setConstant(lambda);
  d.topLeftCorner<3, 3>().diagonal().array() += 2 * mu;
  d.bottomRightCorner<3, 3>().diagonal().setConstant(mu);
  return d;
}

Eigen::Matrix<double, 6, 6> deviatoric_elasticity_matrix(const LinearElasticMaterial& material) {
  // 2 mu (I - m m^T / 3) on the normal block, mu on the (engineering) shears: built
  // directly, since (lambda + 2 mu) - kappa would cancel badly as nu approaches 0.5.
  const double mu = material.shear_modulus();
  Eigen::Matrix<double, 6, 6> d = Eigen::Matrix<double, 6, 6>::Zero();
  d.topLeftCorner<3, 3>().setConstant(-2 * mu / 3);
  d.topLeftCorner<3, 3>().diagonal().array() += 2 * mu;
  d.bottomRightCorner<3, 3>().diagonal().setConstant(mu);
  return d;
}

const char* formulation_name(ElementFormulation formulation) {
  switch (formulation) {
    case ElementFormulation::linear_tet:
      return "linear_tet";
    case ElementFormulation::nodal_pressure_tet:
      return "nodal_pressure_tet";
  }
  return "?";
}

}  // namespace cohaptic
