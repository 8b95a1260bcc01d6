// A second linear-elastic FEM, written differently on purpose, to check the library
// against: shape gradients from inverting the 4x4 matrix [1 x y z], element stiffness in
// Lame form K_ab = V (lambda g_a g_b^T + mu g_b g_a^T + mu (g_a . g_b) I), Eigen's
// SimplicialLDLT instead of CHOLMOD, constraints by partitioning. Units: SI.
#pragma once

#include <Eigen/Core>
#include <map>
#include <vector>

#include "common/mesh/tet_mesh.h"

namespace cohaptic::testing {

Eigen::Matrix<double, 12, 12> independent_tet_stiffness(const Eigen::Matrix<double, 3, 4>& corners,
                                                        double youngs_modulus,
                                                        double poisson_ratio);

struct IndependentSolution {
  Eigen::VectorXd displacement;  ///< 3N
  Eigen::VectorXd reaction;      ///< K u - f, 3N
};

/// Static solve: `fixed` dofs are zero, `prescribed` maps dof -> value, `loads` is 3N or empty.
IndependentSolution independent_static_solve(const TetMesh& mesh, double youngs_modulus,
                                             double poisson_ratio, const std::vector<bool>& fixed,
                                             const std::map<int, double>& prescribed,
                                             const Eigen::VectorXd& loads = {});

}  // namespace cohaptic::testing
