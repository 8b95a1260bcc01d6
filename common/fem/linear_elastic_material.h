// Isotropic linear elastic material and its elasticity matrix.
//
// Units: Young's modulus E in Pa; Poisson's ratio nu dimensionless, -1 < nu < 0.5 (the
// displacement formulation has no solution at 0.5 and locks as nu approaches it).
// Voigt order of strain and stress: xx, yy, zz, yz, xz, xy with engineering shear strains.
#pragma once

#include <Eigen/Core>

namespace cohaptic {

/// How the tetrahedra discretise the material.
enum class ElementFormulation {
  /// Plain linear (constant-strain) tetrahedra: exact for constant strain, but they lock in
  /// bending and ever more as nu approaches 0.5 (too stiff).
  linear_tet,
  /// Average-nodal-pressure tetrahedra (Bonet & Burton 1998): the deviatoric energy per
  /// element as usual, the volumetric energy from dilatations averaged over each node's
  /// tetrahedra, which removes volumetric locking; K couples nodes up to two edges apart.
  nodal_pressure_tet,
};

struct LinearElasticMaterial {
  double youngs_modulus = 0;  ///< E [Pa], > 0
  double poisson_ratio = 0;   ///< nu, in (-1, 0.5)
  ElementFormulation formulation = ElementFormulation::linear_tet;

  double lame_lambda() const {
    return youngs_modulus * poisson_ratio / ((1 + poisson_ratio) * (1 - 2 * poisson_ratio));
  }
  double shear_modulus() const { return youngs_modulus / (2 * (1 + poisson_ratio)); }
  double bulk_modulus() const { return youngs_modulus / (3 * (1 - 2 * poisson_ratio)); }
};

/// Throws cohaptic::Error naming the bad parameter if E or nu is out of range or not finite.
void validate(const LinearElasticMaterial& material);

/// The 6x6 matrix D with sigma = D epsilon (Voigt order above).
Eigen::Matrix<double, 6, 6> elasticity_matrix(const LinearElasticMaterial& material);

/// The deviatoric part of D: D - kappa m m^T with m = (1, 1, 1, 0, 0, 0), kappa the bulk modulus.
Eigen::Matrix<double, 6, 6> deviatoric_elasticity_matrix(const LinearElasticMaterial& material);

/// The scene-file name of a formulation ("linear_tet", "nodal_pressure_tet").
const char* formulation_name(ElementFormulation formulation);

}  // namespace cohaptic
