#include "common/fem/linear_elastic_material.h"

#include <cmath>
#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {

void validate(const LinearElasticMaterial& material) {
  if (!std::isfinite(material.youngs_modulus) || material.youngs_modulus <= 0)
    throw Error(fmt::format("Young's modulus must be a positive number of pascals, got {}", material.youngs_modulus));
  if (!std::isfinite(material.poisson_ratio) || material.poisson_ratio <= -1 || material.poisson_ratio >= 0.5)
    throw Error(fmt::format("Poisson's ratio must lie in (-1, 0.5), got {}", material.poisson_ratio));
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
  Eigen::Matrix<double, 6, 6> d = elasticity_matrix(material);
  d.topLeftCorner<3, 3>().array() -= material.bulk_modulus();
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
