#include "common/fem/schur_compliance.h"

#include <fmt/format.h>

#include <vector>

#include "common/fem/cholmod_view.h"
#include "common/fem/spd_inverse_from_factor.h"
#include "common/util/blas_threads.h"
#include "common/util/error.h"

namespace cohaptic {

namespace {

// A fill-reducing order of `k_ii`: CHOLMOD's nested dissection (NESDIS), which on the
// brain's meshes leaves a few per cent fewer flops for the Schur complement's updates than
// its default choice (AMD, or METIS where AMD fills badly), that default where CHOLMOD was
// built without METIS.
std::vector<int> fill_reducing_order(const SparseMatrix& k_ii) {
  OwnedCholmodFactor analysis;
  analysis.common.nmethods = 1;
  analysis.common.method[0].ordering = CHOLMOD_NESDIS;
  cholmod_sparse view = cholmod_view_of(k_ii);
  analysis.factor = cholmod_analyze(&view, &analysis.common);
  if (analysis.factor == nullptr && analysis.common.status == CHOLMOD_NOT_INSTALLED) {
    analysis.common.status = CHOLMOD_OK;
    analysis.common.nmethods = 0;
    analysis.factor = cholmod_analyze(&view, &analysis.common);
  }
  if (analysis.factor == nullptr || analysis.common.status < CHOLMOD_OK)
    throw NumericalError(fmt::format("CHOLMOD could not order the {0}x{0} interior (status {1})",
                                     k_ii.rows(), analysis.common.status));
  const int* perm = static_cast<const int*>(analysis.factor->Perm);
  return std::vector<int>(perm, perm + k_ii.rows());
}

}  // namespace

Eigen::MatrixXd schur_compliance(const SparseMatrix& k, std::span<const int> rows,
                                 ProgressLog* progress) {
  const auto n = static_cast<int>(k.rows());
  const auto m = static_cast<int>(rows.size());
  std::vector<char> is_row(static_cast<std::size_t>(n), 0);
  for (int row : rows) {
    if (row < 0 || row >= n)
      throw Error(fmt::format("schur compliance: row {} outside the {}x{} matrix", row, n, n));
    if (is_row[static_cast<std::size_t>(row)])
      throw Error(fmt::format("schur compliance: row {} listed twice", row));
    is_row[static_cast<std::size_t>(row)] = 1;
  }
  if (m == 0) return Eigen::MatrixXd(0, 0);

  // The order: the interior in its fill-reducing order, then the rows as given. Kept as
  // given (no postordering), so the factor's last m columns are the rows.
  std::vector<int> interior;
  interior.reserve(static_cast<std::size_t>(n - m));
  for (int i = 0; i < n; ++i)
    if (!is_row[static_cast<std::size_t>(i)]) interior.push_back(i);
  std::vector<int> order;
  order.reserve(static_cast<std::size_t>(n));
  if (!interior.empty())
    for (int position : fill_reducing_order(restrict_to_dofs(k, interior)))
      order.push_back(interior[static_cast<std::size_t>(position)]);
  order.insert(order.end(), rows.begin(), rows.end());

  OwnedCholmodFactor owned;
  cholmod_common& c = owned.common;
  c.nmethods = 1;
  c.method[0].ordering = CHOLMOD_GIVEN;
  c.postorder = 0;
  cholmod_sparse view = cholmod_view_of(k);
  owned.factor = cholmod_analyze_p(&view, order.data(), nullptr, 0, &c);
  if (owned.factor == nullptr || c.status < CHOLMOD_OK)
    throw NumericalError(
        fmt::format("CHOLMOD analysis of a {0}x{0} matrix failed (status {1})", n, c.status));
  cholmod_factor& f = *owned.factor;
  const int* perm = static_cast<const int*>(f.Perm);
  for (int i = 0; i < n; ++i)
    if (perm[i] != order[static_cast<std::size_t>(i)])
      throw NumericalError("CHOLMOD did not keep the order given for the Schur complement");
  const double factor_flops = c.fl;  // as the analysis counts them
  if (progress) {
    progress->set_total(factor_flops + spd_inverse_flops(m));
    progress->set_phase(fmt::format("factorising K ({} dofs, the {} rows last)", n, m));
    progress->begin_part(factor_flops, dense_flop_rate());
  }
  bool factored = false;
  {
    const ScopedBlasThreads blas(kFactorBlasThreads);
    factored = cholmod_factorize(&view, &f, &c) != 0;
  }
  if (progress) progress->add(factor_flops);
  if (!factored || c.status != CHOLMOD_OK)
    throw NumericalError(
        c.status == CHOLMOD_NOT_POSDEF
            ? fmt::format("the stiffness matrix is not positive definite (first failure at row {})",
                          perm[f.minor < static_cast<std::size_t>(n) ? f.minor : 0])
            : fmt::format("CHOLMOD factorisation of a {0}x{0} matrix failed (status {1})", n,
                          c.status));
  if (!f.is_super || !f.is_ll)
    throw NumericalError("CHOLMOD gave no supernodal LL' factor for the Schur complement");

  // The trailing m x m block of L (rows and columns from n - m on, in the rows' order): the
  // supernodes that hold those columns, each a dense column-major block of its rows.
  const int first = n - m;
  Eigen::MatrixXd l_rr = Eigen::MatrixXd::Zero(m, m);
  const int* super = static_cast<const int*>(f.super);
  const int* row_start = static_cast<const int*>(f.pi);
  const int* value_start = static_cast<const int*>(f.px);
  const int* row_index = static_cast<const int*>(f.s);
  const double* values = static_cast<const double*>(f.x);
  for (std::size_t s = 0; s < f.nsuper; ++s) {
    if (super[s + 1] <= first) continue;
    const int height = row_start[s + 1] - row_start[s];
    for (int column = std::max(super[s], first); column < super[s + 1]; ++column)
      for (int r = column - super[s]; r < height; ++r) {  // from the diagonal down
        const int row = row_index[row_start[s] + r];
        l_rr(row - first, column - first) =
            values[static_cast<std::size_t>(value_start[s]) +
                   static_cast<std::size_t>(column - super[s]) * static_cast<std::size_t>(height) +
                   static_cast<std::size_t>(r)];
      }
  }

  if (progress) progress->set_phase("inverting the rows' Schur complement");
  invert_spd_from_factor(l_rr, progress);
  return l_rr;
}

std::size_t compute_row_columns_by_schur(ComplianceColumns& columns, const SparseMatrix& k_ff,
                                         const DofMap& dofs, ProgressLog* progress) {
  const std::vector<int>& nodes = columns.row_nodes();
  bool missing = false;
  for (int node : nodes) missing = missing || !columns.has_column(node);
  if (!missing) return 0;
  // The free dofs of the row nodes, and where each sits among the columns' 3 |rows| rows.
  std::vector<int> free_rows, position;
  for (std::size_t r = 0; r < nodes.size(); ++r)
    for (int axis = 0; axis < 3; ++axis)
      if (const int free = dofs.free_index[static_cast<std::size_t>(3 * nodes[r] + axis)];
          free >= 0) {
        free_rows.push_back(free);
        position.push_back(static_cast<int>(3 * r) + axis);
      }
  const Eigen::MatrixXd l = schur_compliance(k_ff, free_rows, progress);
  std::vector<Eigen::Index> first_free(nodes.size() * 3, -1);
  for (std::size_t k = 0; k < position.size(); ++k)
    first_free[static_cast<std::size_t>(position[k])] = static_cast<Eigen::Index>(k);
  std::size_t added = 0;
  const auto rows = static_cast<Eigen::Index>(3 * nodes.size());
  for (std::size_t r = 0; r < nodes.size(); ++r) {
    if (columns.has_column(nodes[r])) continue;
    ComplianceColumn column = ComplianceColumn::Zero(rows, 3);
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Index j = first_free[3 * r + static_cast<std::size_t>(axis)];
      if (j < 0) continue;  // a fixed axis carries no force: its column stays zero
      for (std::size_t k = 0; k < position.size(); ++k)
        column(position[k], axis) = l(static_cast<Eigen::Index>(k), j);
    }
    columns.insert_column(nodes[r], std::move(column));
    ++added;
  }
  return added;
}

}  // namespace cohaptic
