// The Schur-complement route to the compliance among a set of dofs (schur_compliance.h)
// against the dense inverse of K and against ComplianceColumns' solves, on the paper's cube: equal
// to round-off, exactly symmetric, the same bits run to run, and a K that is not positive definite
// refused.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "common/fem/schur_compliance.h"
#include "common/fem/spd_inverse_from_factor.h"
#include "common/model/model.h"
#include "common/scene/load_scene.h"
#include "common/util/blas_threads.h"
#include "common/util/error.h"
#include "support/cube_scene.h"

namespace cohaptic {
namespace {

// The paper's cube, its rear face fixed, its top touchable.
Model soft_cube(int divisions) {
  testing::CubeSceneOptions cube;
  cube.divisions = divisions;
  return build_model(parse_scene(testing::cube_scene_yaml(cube), "cube.yaml"));
}

TEST(SchurCompliance, EqualsTheDenseInverseAmongAnySetOfDofsAndIsExactlySymmetric) {
  const Model model = soft_cube(4);
  const ElasticBody& body = single_elastic_body(model);
  const SparseMatrix k_ff = restrict_to_dofs(body.stiffness, body.dofs.free_dofs);
  const Eigen::MatrixXd dense(k_ff);
  const Eigen::MatrixXd inverse =
      dense.llt().solve(Eigen::MatrixXd::Identity(dense.rows(), dense.cols()));
  const int n = static_cast<int>(k_ff.rows());
  // Scattered dofs out of order, a contiguous block, a single dof, and every dof (no interior).
  std::vector<std::vector<int>> sets = {{n - 1, 5, 17, 2, 60, 33, n / 2}, {}, {n / 3}, {}};
  for (int i = 40; i < 100; ++i) sets[1].push_back(i);
  for (int i = 0; i < n; ++i) sets[3].push_back(i);
  for (const std::vector<int>& rows : sets) {
    SCOPED_TRACE(fmt::format("{} rows", rows.size()));
    const Eigen::MatrixXd l = schur_compliance(k_ff, rows);
    ASSERT_EQ(l.rows(), static_cast<Eigen::Index>(rows.size()));
    Eigen::MatrixXd expected(l.rows(), l.cols());
    for (std::size_t i = 0; i < rows.size(); ++i)
      for (std::size_t j = 0; j < rows.size(); ++j)
        expected(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) =
            inverse(rows[i], rows[j]);
    EXPECT_LE((l - expected).norm(), 1e-10 * expected.norm());
    EXPECT_EQ(l, l.transpose());
    EXPECT_EQ(l, schur_compliance(k_ff, rows)) << "not the same bits a second time";
  }
}

TEST(SchurCompliance, FillsTheRowNodesColumnsAsTheSolvesDoWithFixedAxesZero) {
  const Model model = soft_cube(5);
  const ElasticBody& body = single_elastic_body(model);
  const SparseMatrix k_ff = restrict_to_dofs(body.stiffness, body.dofs.free_dofs);
  // Rows: the top face and a few nodes of the fixed bottom (their columns and rows are zero).
  std::vector<int> rows = body.touchable_nodes;
  int fixed_rows = 0;
  for (int node = 0; node < body.mesh.node_count() && fixed_rows < 3; ++node)
    if (body.dofs.is_fixed(node, 0)) {
      rows.push_back(node);
      ++fixed_rows;
    }
  ASSERT_EQ(fixed_rows, 3);
  ComplianceColumns solved(body.free_factor, body.dofs, rows);
  solved.compute_columns(rows);
  ComplianceColumns schur(body.free_factor, body.dofs, rows);
  schur.insert_column(rows[1], solved.column(rows[1]));  // one known already: kept, not recomputed
  EXPECT_EQ(compute_row_columns_by_schur(schur, k_ff, body.dofs), rows.size() - 1);
  EXPECT_EQ(schur.column(rows[1]), solved.column(rows[1]));
  for (int node : rows) {
    const ComplianceColumn& expected = solved.column(node);
    EXPECT_LE((schur.column(node) - expected).norm(), 1e-10 * expected.norm() + 1e-300)
        << "node " << node;
    if (body.dofs.is_fixed(node, 0)) {
      EXPECT_TRUE(schur.column(node).isZero(0)) << "fixed node " << node;
    }
  }
  EXPECT_EQ(compute_row_columns_by_schur(schur, k_ff, body.dofs), 0u) << "nothing left to compute";
}

// The dense inverse from a factor (LAPACK on BLAS threads) against Eigen's own: sizes from
// one to several of OpenBLAS's blocks; the same bits a second time, whatever BLAS's thread
// count outside it.
TEST(SchurCompliance, TheInverseFromAFactorEqualsADirectInverseWithTheSameBitsEachTime) {
  for (int m : {1, 7, 500}) {
    SCOPED_TRACE(fmt::format("m = {}", m));
    const Eigen::MatrixXd a = Eigen::MatrixXd::Random(m, m);
    const Eigen::MatrixXd s = a * a.transpose() + m * Eigen::MatrixXd::Identity(m, m);
    const Eigen::LLT<Eigen::MatrixXd> llt(s);
    const Eigen::MatrixXd expected = llt.solve(Eigen::MatrixXd::Identity(m, m));
    Eigen::MatrixXd inverse = llt.matrixL();
    invert_spd_from_factor(inverse);
    EXPECT_LE((inverse - expected).norm(), 1e-12 * expected.norm());
    EXPECT_EQ(inverse, inverse.transpose());
    for (int outside : {1, 3}) {
      const ScopedBlasThreads blas(outside);
      Eigen::MatrixXd again = llt.matrixL();
      invert_spd_from_factor(again);
      EXPECT_EQ(again, inverse) << "BLAS on " << outside << " threads outside";
    }
  }
}

TEST(SchurCompliance, AFactorWithAZeroOnItsDiagonalIsRefused) {
  Eigen::MatrixXd factor = Eigen::MatrixXd::Identity(4, 4);
  factor(2, 2) = 0;
  EXPECT_THROW(invert_spd_from_factor(factor), NumericalError);
}

TEST(SchurCompliance, AMatrixThatIsNotPositiveDefiniteIsRefused) {
  SparseMatrix k(3, 3);
  k.insert(0, 0) = 1;
  k.insert(1, 1) = -1;
  k.insert(2, 2) = 1;
  k.makeCompressed();
  EXPECT_THROW(schur_compliance(k, std::vector<int>{2}), NumericalError);
  EXPECT_THROW(schur_compliance(k, std::vector<int>{1}), NumericalError);
  EXPECT_THROW(schur_compliance(k, std::vector<int>{1, 1}), Error);
  EXPECT_THROW(schur_compliance(k, std::vector<int>{3}), Error);
}

}  // namespace
}  // namespace cohaptic
