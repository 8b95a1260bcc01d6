// Stiffness of one linear (4-node) tetrahedron.
//
// K_e = V B^T D B, exact for constant strain. B maps the 12 nodal displacements
// (node-major: u0x u0y u0z u1x ...) to the Voigt strain. Units: positions in m,
// D in Pa, K_e in N/m. The element must have positive volume.
#pragma once

#include <Eigen/Core>

namespace cohaptic {

using TetStiffness = Eigen::Matrix<double, 12, 12>;
using TetStrainMatrix = Eigen::Matrix<double, 6, 12>;

/// Shape-function gradients (one column per node) of the tetrahedron x0..x3, and its
/// signed volume in `volume`.
Eigen::Matrix<double, 3, 4> tet_shape_gradients(const Eigen::Matrix<double, 3, 4>& corners,
                                                double& volume);

/// Strain-displacement matrix B from the shape-function gradients.
TetStrainMatrix tet_strain_matrix(const Eigen::Matrix<double, 3, 4>& gradients);

/// K_e for the tetrahedron with corners x0..x3 (columns) and elasticity matrix D.
TetStiffness tet_stiffness(const Eigen::Matrix<double, 3, 4>& corners,
                           const Eigen::Matrix<double, 6, 6>& elasticity);

}  // namespace cohaptic
