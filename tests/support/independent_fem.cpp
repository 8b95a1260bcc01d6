#include "support/independent_fem.h"

#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <stdexcept>

namespace cohaptic::testing {

Eigen::Matrix<double, 12, 12> independent_tet_stiffness(const Eigen::Matrix<double, 3, 4>& corners,
                                                        double youngs_modulus,
                                                        double poisson_ratio) {
  Eigen::Matrix4d p;
  for (int a = 0; a < 4; ++a) p.row(a) << 1.0, corners(0, a), corners(1, a), corners(2, a);
  // N_a(x) = c_a . (1, x, y, z) with C = P^-1 (columns are the coefficient vectors).
  const Eigen::Matrix4d c = p.inverse();
  const double volume = std::abs(p.determinant()) / 6.0;
  const double lambda =
      youngs_modulus * poisson_ratio / ((1 + poisson_ratio) * (1 - 2 * poisson_ratio));
  const double mu = youngs_modulus / (2 * (1 + poisson_ratio));
  Eigen::Matrix<double, 12, 12> k;
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) {
      const Eigen::Vector3d ga = c.col(a).tail<3>(), gb = c.col(b).tail<3>();
      k.block<3, 3>(3 * a, 3 * b) =
          volume * (lambda * ga * gb.transpose() + mu * gb * ga.transpose() +
                    mu * ga.dot(gb) * Eigen::Matrix3d::Identity());
    }
  return k;
}

IndependentSolution independent_static_solve(const TetMesh& mesh, double youngs_modulus,
                                             double poisson_ratio, const std::vector<bool>& fixed,
                                             const std::map<int, double>& prescribed,
                                             const Eigen::VectorXd& loads) {
  const int n = 3 * mesh.node_count();
  std::vector<Eigen::Triplet<double>> triplets;
  for (const Tet& tet : mesh.tets) {
    Eigen::Matrix<double, 3, 4> corners;
    for (int a = 0; a < 4; ++a) corners.col(a) = mesh.nodes.col(tet[a]);
    const auto ke = independent_tet_stiffness(corners, youngs_modulus, poisson_ratio);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            triplets.emplace_back(3 * tet[a] + i, 3 * tet[b] + j, ke(3 * a + i, 3 * b + j));
  }
  Eigen::SparseMatrix<double> k(n, n);
  k.setFromTriplets(triplets.begin(), triplets.end());

  IndependentSolution solution;
  solution.displacement = Eigen::VectorXd::Zero(n);
  std::vector<int> unknown_index(static_cast<std::size_t>(n), -1);
  std::vector<int> unknown;
  for (int dof = 0; dof < n; ++dof) {
    if (const auto it = prescribed.find(dof); it != prescribed.end())
      solution.displacement[dof] = it->second;
    else if (!fixed[dof]) {
      unknown_index[dof] = static_cast<int>(unknown.size());
      unknown.push_back(dof);
    }
  }
  Eigen::VectorXd rhs = -(k * solution.displacement);
  if (loads.size() == n) rhs += loads;
  const auto m = static_cast<int>(unknown.size());
  std::vector<Eigen::Triplet<double>> reduced;
  for (int col = 0; col < k.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(k, col); it; ++it)
      if (unknown_index[it.row()] >= 0 && unknown_index[col] >= 0)
        reduced.emplace_back(unknown_index[it.row()], unknown_index[col], it.value());
  Eigen::SparseMatrix<double> k_uu(m, m);
  k_uu.setFromTriplets(reduced.begin(), reduced.end());
  Eigen::VectorXd rhs_u(m);
  for (int i = 0; i < m; ++i) rhs_u[i] = rhs[unknown[i]];
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(k_uu);
  if (ldlt.info() != Eigen::Success)
    throw std::runtime_error("independent FEM: factorisation failed");
  const Eigen::VectorXd u_u = ldlt.solve(rhs_u);
  for (int i = 0; i < m; ++i) solution.displacement[unknown[i]] = u_u[i];
  solution.reaction = k * solution.displacement;
  if (loads.size() == n) solution.reaction -= loads;
  return solution;
}

}  // namespace cohaptic::testing
