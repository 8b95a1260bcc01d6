#include "common/fem/assemble_stiffness.h"

#include <cmath>

#include "common/fem/tet_stiffness.h"

namespace cohaptic {
namespace {

using Triplets = std::vector<Eigen::Triplet<double, int>>;

// Sum over the tetrahedra of V_e B_e^T D B_e.
SparseMatrix element_stiffness(const TetMesh& mesh, const Eigen::Matrix<double, 6, 6>& d) {
  Triplets triplets;
  triplets.reserve(static_cast<std::size_t>(mesh.tet_count()) * 144);
  Eigen::Matrix<double, 3, 4> corners;
  for (const Tet& tet : mesh.tets) {
    for (int i = 0; i < 4; ++i) corners.col(i) = mesh.nodes.col(tet[i]);
    const TetStiffness ke = tet_stiffness(corners, d);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b)
            triplets.emplace_back(3 * tet[i] + a, 3 * tet[j] + b, ke(3 * i + a, 3 * j + b));
  }
  const int n = 3 * mesh.node_count();
  SparseMatrix k(n, n);
  k.setFromTriplets(triplets.begin(), triplets.end());
  return k;
}

// The volumetric stiffness of average-nodal-pressure tetrahedra. Node a owns the volume
// V_a = sum over its tetrahedra of V_e / 4 and the dilatation
//   theta_a = (1 / V_a) sum over its tetrahedra of (V_e / 4) div_e(u),
// and the volumetric energy is kappa / 2 sum_a V_a theta_a^2. With row a of Q equal to
// sqrt(V_a) d theta_a / du, K_vol = kappa Q^T Q.
SparseMatrix nodal_volumetric_stiffness(const TetMesh& mesh, double bulk_modulus) {
  Eigen::VectorXd nodal_volume = Eigen::VectorXd::Zero(mesh.node_count());
  Triplets weighted_divergence;  // (a, dof) -> sum of (V_e / 4) d div_e / d u_dof
  weighted_divergence.reserve(static_cast<std::size_t>(mesh.tet_count()) * 48);
  Eigen::Matrix<double, 3, 4> corners;
  for (const Tet& tet : mesh.tets) {
    for (int i = 0; i < 4; ++i) corners.col(i) = mesh.nodes.col(tet[i]);
    double volume = 0;
    const Eigen::Matrix<double, 3, 4> gradients = tet_shape_gradients(corners, volume);
    const double share = volume / 4;
    for (int a = 0; a < 4; ++a) {
      nodal_volume[tet[a]] += share;
      for (int b = 0; b < 4; ++b)
        for (int axis = 0; axis < 3; ++axis)
          weighted_divergence.emplace_back(tet[a], 3 * tet[b] + axis, share * gradients(axis, b));
    }
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> q(mesh.node_count(), 3 * mesh.node_count());
  q.setFromTriplets(weighted_divergence.begin(), weighted_divergence.end());
  for (int a = 0; a < mesh.node_count(); ++a) {
    if (nodal_volume[a] <= 0) continue;  // a node no tetrahedron uses has no dilatation
    q.row(a) /= std::sqrt(nodal_volume[a]);
  }
  const SparseMatrix qt = q.transpose();
  SparseMatrix k = bulk_modulus * (qt * q);
  k.prune(0.0);
  return k;
}

}  // namespace

SparseMatrix assemble_stiffness(const TetMesh& mesh, const LinearElasticMaterial& material) {
  switch (material.formulation) {
    case ElementFormulation::nodal_pressure_tet:
      return element_stiffness(mesh, deviatoric_elasticity_matrix(material)) +
             nodal_volumetric_stiffness(mesh, material.bulk_modulus());
    case ElementFormulation::linear_tet:
      break;
  }
  return element_stiffness(mesh, elasticity_matrix(material));
}

SparseMatrix restrict_to_dofs(const SparseMatrix& k, const std::vector<int>& dofs) {
  std::vector<int> position(static_cast<std::size_t>(k.rows()), -1);
  for (int i = 0; i < static_cast<int>(dofs.size()); ++i) position[dofs[i]] = i;
  std::vector<Eigen::Triplet<double, int>> triplets;
  triplets.reserve(static_cast<std::size_t>(k.nonZeros()));
  for (int col = 0; col < k.outerSize(); ++col) {
    if (position[col] < 0) continue;
    for (SparseMatrix::InnerIterator it(k, col); it; ++it)
      if (position[it.row()] >= 0)
        triplets.emplace_back(position[it.row()], position[col], it.value());
  }
  const auto m = static_cast<int>(dofs.size());
  SparseMatrix restricted(m, m);
  restricted.setFromTriplets(triplets.begin(), triplets.end());
  return restricted;
}

}  // namespace cohaptic
