#include "common/fem/tet_stiffness.h"

#include <Eigen/LU>

namespace cohaptic {

Eigen::Matrix<double, 3, 4> tet_shape_gradients(const Eigen::Matrix<double, 3, 4>& corners,
                                                double& volume) {
  Eigen::Matrix3d edges;
  edges << corners.col(1) - corners.col(0), corners.col(2) - corners.col(0),
      corners.col(3) - corners.col(0);
  volume = edges.determinant() / 6.0;
  // Barycentric coordinates xi = J^-1 (x - x0): the gradient of N_i (i = 1..3) is row i of J^-1.
  const Eigen::Matrix3d inverse = edges.inverse();
  Eigen::Matrix<double, 3, 4> gradients;
  gradients.rightCols<3>() = inverse.transpose();
  gradients.col(0) = -gradients.rightCols<3>().rowwise().sum();
  return gradients;
}

TetStrainMatrix tet_strain_matrix(const Eigen::Matrix<double, 3, 4>& gradients) {
  TetStrainMatrix b = TetStrainMatrix::Zero();
  for (int i = 0; i < 4; ++i) {
    const double gx = gradients(0, i), gy = gradients(1, i), gz = gradients(2, i);
    const int c = 3 * i;
    b(0, c) = gx;
    b(1, c + 1) = gy;
    b(2, c + 2) = gz;
    b(3, c + 1) = gz;
    b(3, c + 2) = gy;
    b(4, c) = gz;
    b(4, c + 2) = gx;
    b(5, c) = gy;
    b(5, c + 1) = gx;
  }
  return b;
}

TetStiffness tet_stiffness(const Eigen::Matrix<double, 3, 4>& corners,
                           const Eigen::Matrix<double, 6, 6>& elasticity) {
  double volume = 0;
  const TetStrainMatrix b = tet_strain_matrix(tet_shape_gradients(corners, volume));
  return volume * b.transpose() * elasticity * b;
}

}  // namespace cohaptic
