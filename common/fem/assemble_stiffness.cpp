#include "common/fem/assemble_stiffness.h"

#include "common/fem/tet_stiffness.h"

namespace cohaptic {

SparseMatrix assemble_stiffness(const TetMesh& mesh, const LinearElasticMaterial& material) {
  const Eigen::Matrix<double, 6, 6> d = elasticity_matrix(material);
  std::vector<Eigen::Triplet<double, int>> triplets;
  triplets.reserve(static_cast<std::size_t>(mesh.tet_count()) * 144);
  Eigen::Matrix<double, 3, 4> corners;
  for (const Tet& tet : mesh.tets) {
    for (int i = 0; i < 4; ++i) corners.col(i) = mesh.nodes.col(tet[i]);
    const TetStiffness ke = tet_stiffness(corners, d);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) triplets.emplace_back(3 * tet[i] + a, 3 * tet[j] + b, ke(3 * i + a, 3 * j + b));
  }
  const int n = 3 * mesh.node_count();
  SparseMatrix k(n, n);
  k.setFromTriplets(triplets.begin(), triplets.end());
  return k;
}

SparseMatrix restrict_to_dofs(const SparseMatrix& k, const std::vector<int>& dofs) {
  std::vector<int> position(static_cast<std::size_t>(k.rows()), -1);
  for (int i = 0; i < static_cast<int>(dofs.size()); ++i) position[dofs[i]] = i;
  std::vector<Eigen::Triplet<double, int>> triplets;
  triplets.reserve(static_cast<std::size_t>(k.nonZeros()));
  for (int col = 0; col < k.outerSize(); ++col) {
    if (position[col] < 0) continue;
    for (SparseMatrix::InnerIterator it(k, col); it; ++it)
      if (position[it.row()] >= 0) triplets.emplace_back(position[it.row()], position[col], it.value());
  }
  const auto m = static_cast<int>(dofs.size());
  SparseMatrix restricted(m, m);
  restricted.setFromTriplets(triplets.begin(), triplets.end());
  return restricted;
}

}  // namespace cohaptic
