#include "common/mass_spring/node_backing.h"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "common/contact/unilateral_contact_solve.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

// The solve's work budget in full-set trials: block principal pivoting on a positive
// definite A ends in a few trials; this many means something is wrong.
constexpr double kBackingSolveTrials = 20;

bool backing_solve_fits(const NodeBacking& backing, const NodeBackingSolve& solve) noexcept {
  const auto count = static_cast<Eigen::Index>(backing.nodes.size());
  return solve.pushes.size() == count && solve.gaps.size() == count &&
         solve.solved.size() == count && static_cast<Eigen::Index>(solve.active.size()) == count &&
         static_cast<Eigen::Index>(solve.order.size()) == count && solve.factor.rows() == count &&
         solve.factor.cols() == count;
}

}  // namespace

void prepare_backing_solve(NodeBackingSolve& solve, const NodeBacking& backing) {
  const auto count = static_cast<Eigen::Index>(backing.nodes.size());
  solve.active.assign(backing.nodes.size(), 0);
  solve.pushes = Eigen::VectorXd::Zero(count);
  solve.gaps = Eigen::VectorXd::Zero(count);
  solve.solved = Eigen::VectorXd::Zero(count);
  solve.factor = Eigen::MatrixXd::Zero(count, count);
  solve.order.assign(backing.nodes.size(), 0);
}

void add_node_backing_forces(const NodeBacking& backing, NodeBackingSolve& solve,
                             const Eigen::Ref<const Eigen::Matrix3Xd>& positions,
                             const Eigen::Ref<const Eigen::Matrix3Xd>& velocities,
                             Eigen::Ref<Eigen::Matrix3Xd> forces) noexcept {
  const auto count = static_cast<Eigen::Index>(backing.nodes.size());
  if (count == 0) return;
  ++solve.evaluations;
  if (!backing_solve_fits(backing, solve)) {
    ++solve.failures;  // a caller's mistake, counted: no push is better than one from elsewhere
    return;
  }
  bool touching = false;
  for (Eigen::Index i = 0; i < count; ++i) {
    const int node = backing.nodes[static_cast<std::size_t>(i)];
    solve.gaps[i] = (positions.col(node) - backing.targets.segment<3>(3 * i))
                        .dot(backing.normals.segment<3>(3 * i)) +
                    backing.offsets[i];
    touching = touching || solve.gaps[i] < 0;
  }
  if (!touching) {
    // Every gap open: nothing pushes (the solve's answer, without its work).
    solve.pushes.setZero();
    std::fill(solve.active.begin(), solve.active.end(), std::uint8_t{0});
    return;
  }
  const double m = static_cast<double>(count);
  const double budget = kBackingSolveTrials * (m * m * m / 3 + 2 * m * m);
  const UnilateralSolveResult result =
      solve_unilateral_contact(backing.compliance, solve.gaps, solve.active, solve.solved,
                               solve.factor, solve.order, budget);
  if (result.solved) {
    solve.pushes = solve.solved;
  } else {
    // Hold the previous pushes where a node is still behind B's surface, release the rest,
    // and count it: the forces stay bounded and pushing, never made up.
    ++solve.failures;
    for (Eigen::Index i = 0; i < count; ++i) {
      if (!(solve.gaps[i] < 0)) solve.pushes[i] = 0;
      solve.active[static_cast<std::size_t>(i)] = solve.pushes[i] > 0 ? 1 : 0;
    }
  }
  for (Eigen::Index i = 0; i < count; ++i) {
    if (!(solve.pushes[i] > 0)) continue;
    const int node = backing.nodes[static_cast<std::size_t>(i)];
    const Eigen::Vector3d normal = backing.normals.segment<3>(3 * i);
    const double push = solve.pushes[i] - backing.damping[i] * velocities.col(node).dot(normal);
    if (push > 0) forces.col(node) += push * normal;
  }
}

double backing_energy(const NodeBacking& backing,
                      const Eigen::Ref<const Eigen::VectorXd>& pushes) noexcept {
  if (backing.empty()) return 0;
  return 0.5 * pushes.dot(backing.compliance * pushes);
}

NodeBacking sub_network_backing(const NodeBacking& whole,
                                const Eigen::Ref<const Eigen::VectorXd>& pushes,
                                std::span<const std::int32_t> body_nodes) {
  std::vector<Eigen::Index> kept, outside;
  NodeBacking sub;
  for (std::size_t k = 0; k < whole.nodes.size(); ++k) {
    const auto at = std::find(body_nodes.begin(), body_nodes.end(), whole.nodes[k]);
    if (at == body_nodes.end()) {
      outside.push_back(static_cast<Eigen::Index>(k));
      continue;
    }
    sub.nodes.push_back(static_cast<int>(at - body_nodes.begin()));
    kept.push_back(static_cast<Eigen::Index>(k));
  }
  const auto count = static_cast<Eigen::Index>(kept.size());
  sub.compliance.resize(count, count);
  sub.offsets.resize(count);
  sub.damping.resize(count);
  sub.targets.resize(3 * count);
  sub.normals.resize(3 * count);
  for (Eigen::Index a = 0; a < count; ++a) {
    const Eigen::Index i = kept[static_cast<std::size_t>(a)];
    for (Eigen::Index b = 0; b < count; ++b)
      sub.compliance(a, b) = whole.compliance(i, kept[static_cast<std::size_t>(b)]);
    double offset = whole.offsets[i];
    for (Eigen::Index j : outside) offset += whole.compliance(i, j) * pushes[j];
    sub.offsets[a] = offset;
    sub.damping[a] = whole.damping[i];
    sub.targets.segment<3>(3 * a) = whole.targets.segment<3>(3 * i);
    sub.normals.segment<3>(3 * a) = whole.normals.segment<3>(3 * i);
  }
  return sub;
}

void check_node_backing(const NodeBacking& backing, int node_count, const char* what) {
  const auto count = static_cast<Eigen::Index>(backing.nodes.size());
  if (backing.compliance.rows() != count || backing.compliance.cols() != count ||
      backing.offsets.size() != count || backing.damping.size() != count ||
      backing.targets.size() != 3 * count || backing.normals.size() != 3 * count)
    throw Error(fmt::format(
        "{}: the backing of {} nodes needs a {}x{} compliance, {} offsets and dampings and {} "
        "targets and normals, not {}x{}, {}, {}, {} and {}",
        what, count, count, count, count, 3 * count, backing.compliance.rows(),
        backing.compliance.cols(), backing.offsets.size(), backing.damping.size(),
        backing.targets.size(), backing.normals.size()));
  for (std::size_t k = 0; k < backing.nodes.size(); ++k) {
    const int node = backing.nodes[k];
    if (node < 0 || node >= node_count)
      throw Error(
          fmt::format("{}: backed node {} is {}, not a node of the {}", what, k, node, node_count));
    if (std::count(backing.nodes.begin(), backing.nodes.end(), node) > 1)
      throw Error(fmt::format("{}: node {} is backed twice", what, node));
  }
  if (!backing.compliance.allFinite() || !backing.offsets.allFinite() ||
      !backing.damping.allFinite() || !backing.targets.allFinite() || !backing.normals.allFinite())
    throw Error(fmt::format(
        "{}: the backing's compliance, offsets, damping, targets or normals are not finite", what));
  if (count > 0) {
    const double scale = backing.compliance.cwiseAbs().maxCoeff();
    if ((backing.compliance - backing.compliance.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale)
      throw Error(fmt::format("{}: the backing's compliance is not symmetric", what));
    if (backing.compliance.llt().info() != Eigen::Success)
      throw Error(fmt::format("{}: the backing's compliance is not positive definite", what));
  }
  for (Eigen::Index k = 0; k < count; ++k) {
    if (backing.damping[k] < 0)
      throw Error(fmt::format("{}: backed node {} has damping {} N s/m (it may not be negative)",
                              what, k, backing.damping[k]));
    if (std::abs(backing.normals.segment<3>(3 * k).norm() - 1) > 1e-6)
      throw Error(fmt::format("{}: backed node {} has a normal of length {}, not a unit normal",
                              what, k, backing.normals.segment<3>(3 * k).norm()));
  }
}

}  // namespace cohaptic
