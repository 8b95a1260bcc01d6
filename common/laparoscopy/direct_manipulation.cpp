#include "common/laparoscopy/direct_manipulation.h"

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {
namespace {

/// Below this reciprocal condition number of the Gram matrix the points are taken as
/// dependent: the solve would amplify rounding by more than 1e12.
constexpr double kMinReciprocalCondition = 1e-12;

}  // namespace

LatticeControl single_point_manipulation(const LatticeBasis& basis,
                                         const Eigen::Vector3d& displacement) noexcept {
  // The basis sums to one, so sum_i b_i^2 >= 1/64: never zero inside or near the box.
  return displacement * basis.transpose() / basis.squaredNorm();
}

LatticeControl least_squares_manipulation(
    const Eigen::Matrix<double, kLatticeControlPoints, Eigen::Dynamic>& bases,
    const Eigen::Matrix3Xd& displacements) {
  const Eigen::Index m = bases.cols();
  if (m == 0) throw Error("direct manipulation: no point to move");
  if (displacements.cols() != m)
    throw Error(
        fmt::format("direct manipulation: {} bases but {} displacements", m, displacements.cols()));
  const bool fewer = m <= kLatticeControlPoints;
  // B is m x 64 (a row per point); here bases = B^T.
  const Eigen::MatrixXd gram = fewer
                                   ? Eigen::MatrixXd(bases.transpose() * bases)   // B B^T, m x m
                                   : Eigen::MatrixXd(bases * bases.transpose());  // B^T B, 64 x 64
  const Eigen::LLT<Eigen::MatrixXd> factor(gram);
  if (factor.info() != Eigen::Success || !(factor.rcond() > kMinReciprocalCondition))
    throw NumericalError(
        fmt::format("direct manipulation: the {} points' bases are dependent (Gram matrix "
                    "reciprocal condition {:.3g}); "
                    "is a point given twice?",
                    m, factor.info() == Eigen::Success ? factor.rcond() : 0.0));
  // dP^T (64 x 3) = B^T (B B^T)^-1 dQ^T, or (B^T B)^-1 B^T dQ^T.
  const Eigen::MatrixXd solved =
      fewer ? Eigen::MatrixXd(bases * factor.solve(displacements.transpose()))
            : Eigen::MatrixXd(factor.solve(bases * displacements.transpose()));
  return solved.transpose();
}

}  // namespace cohaptic
