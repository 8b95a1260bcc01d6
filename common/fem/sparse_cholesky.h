// SparseCholesky: a supernodal CHOLMOD factorisation of a sparse symmetric positive
// definite matrix (K_ff), and solves against it.
//
// CHOLMOD keeps workspace in its cholmod_common, so solve() mutates internal scratch:
// one thread at a time may use an instance (the server's simulation loop owns it).
// Units are those of the matrix; solve(K, f) gives u for K in N/m and f in N.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>

#include "common/fem/assemble_stiffness.h"

namespace cohaptic {

class SparseCholesky {
 public:
  /// Names row i for error messages, e.g. "node 812 axis y".
  using RowNamer = std::function<std::string(int row)>;

  /// Analyses and factors `matrix` (only its lower triangle is read). Throws
  /// NumericalError naming the row where positive definiteness failed.
  explicit SparseCholesky(const SparseMatrix& matrix, const RowNamer& name_row = {});
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  int size() const { return size_; }

  /// X with matrix * X = rhs (any number of columns).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const;

  /// CHOLMOD's cheap reciprocal condition estimate, (min diag L / max diag L)^2.
  double reciprocal_condition_estimate() const;
  /// Nonzeros stored in the factor (a memory and cost figure for logs and benchmarks).
  double factor_nonzeros() const;
  bool is_supernodal() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int size_ = 0;
};

}  // namespace cohaptic
