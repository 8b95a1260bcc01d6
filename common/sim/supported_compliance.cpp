#include "common/sim/supported_compliance.h"

#include <fmt/format.h>

#include <utility>

#include "common/util/error.h"

namespace cohaptic {

SupportedCompliance::SupportedCompliance(ComplianceSource& base, const DofMap& dofs,
                                         std::vector<int> nodes, const Eigen::Matrix3Xd& normals,
                                         const Eigen::MatrixXd& support_compliance,
                                         const Eigen::VectorXd& rest_gaps)
    : base_(base), nodes_(std::move(nodes)) {
  const auto count = static_cast<Eigen::Index>(nodes_.size());
  if (normals.cols() != count || support_compliance.rows() != count ||
      support_compliance.cols() != count || (rest_gaps.size() != 0 && rest_gaps.size() != count))
    throw Error(
        fmt::format("supported compliance: {} support nodes, {} normals, a {}x{} support "
                    "compliance, {} rest gaps",
                    count, normals.cols(), support_compliance.rows(), support_compliance.cols(),
                    rest_gaps.size()));
  // A fixed axis of A has no row (its L is zero): the support's spring along it does
  // nothing, as K_ff leaves it out. N keeps the free axes only.
  std::vector<std::pair<Eigen::Index, double>> entries;  // (support, normal component) per free dof
  for (Eigen::Index s = 0; s < count; ++s)
    for (int axis = 0; axis < 3; ++axis)
      if (const int node = nodes_[static_cast<std::size_t>(s)]; !dofs.is_fixed(node, axis)) {
        dofs_.push_back(3 * node + axis);
        entries.emplace_back(s, normals(axis, s));
      }
  std::vector<Eigen::Triplet<double>> triplets;
  for (std::size_t row = 0; row < entries.size(); ++row)
    triplets.emplace_back(static_cast<Eigen::Index>(row), entries[row].first, entries[row].second);
  normals_.resize(static_cast<Eigen::Index>(dofs_.size()), count);
  normals_.setFromTriplets(triplets.begin(), triplets.end());
  base_.compute_columns(nodes_);
  const Eigen::MatrixXd block_times_normals = base_.dof_block(dofs_, dofs_) * normals_;
  const Eigen::MatrixXd coupled = support_compliance + normals_.transpose() * block_times_normals;
  coupled_.compute((coupled + coupled.transpose()) / 2);
  if (coupled_.info() != Eigen::Success)
    throw Error(
        fmt::format("supported compliance: the {} supporting nodes' coupled compliance is not "
                    "positive definite "
                    "(neither A nor the support gives way along a normal)",
                    count));
  if (rest_gaps.size() != 0 && !rest_gaps.isZero(0))
    rest_loads_ = normals_ * Eigen::VectorXd(-coupled_.solve(rest_gaps));
}

Eigen::VectorXd SupportedCompliance::rest_displacement(std::span<const int> dofs) {
  if (!loads_at_rest()) return Eigen::VectorXd::Zero(static_cast<Eigen::Index>(dofs.size()));
  return base_.dof_block(dofs, dofs_) * rest_loads_;
}

void SupportedCompliance::compute_columns(const std::vector<int>& nodes) {
  base_.compute_columns(nodes);
}

Eigen::MatrixXd SupportedCompliance::dof_block(std::span<const int> row_dofs,
                                               std::span<const int> col_dofs) {
  const Eigen::MatrixXd rows =
      Eigen::MatrixXd(base_.dof_block(row_dofs, dofs_) * normals_);  // L_XS N
  const Eigen::MatrixXd cols = Eigen::MatrixXd(base_.dof_block(col_dofs, dofs_) *
                                               normals_);  // L_YS N = (N^T L_SY)^T, L symmetric
  return base_.dof_block(row_dofs, col_dofs) - rows * coupled_.solve(cols.transpose());
}

}  // namespace cohaptic
