#include "common/condense/cholesky_rank_update.h"

#include <fmt/format.h>

#include <cmath>

#include "common/util/error.h"

namespace cohaptic {

void cholesky_rank_update(Eigen::Ref<Eigen::MatrixXd> g, Eigen::Ref<Eigen::MatrixXd> w) {
  const Eigen::Index n = g.rows();
  if (g.cols() != n || w.rows() != n)
    throw Error(fmt::format("cholesky_rank_update: a {} x {} factor and {} update rows", n, g.cols(), w.rows()));
  // Column by column, so that both the factor's column and the update vectors are
  // contiguous and the loops vectorise; each of the k rotations sweeps a column in cache.
  for (Eigen::Index j = 0; j < n; ++j) {
    const Eigen::Index below = n - j - 1;
    for (Eigen::Index r = 0; r < w.cols(); ++r) {
      const double diagonal = g(j, j);
      const double radius = std::hypot(diagonal, w(j, r));
      const double inverse_cosine = diagonal / radius, sine = w(j, r) / diagonal;
      g(j, j) = radius;
      auto column = g.col(j).tail(below);
      auto update = w.col(r).tail(below);
      column = (column + sine * update) * inverse_cosine;
      update = update * (radius / diagonal) - sine * column;
    }
  }
}

}  // namespace cohaptic
