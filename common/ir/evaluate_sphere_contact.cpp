#include "common/ir/evaluate_sphere_contact.h"

#include <algorithm>
#include <array>

#include "common/contact/sphere_contact.h"
#include "common/contact/working_set_contact_solve.h"

namespace cohaptic {
namespace {

using ContactMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxSphereContacts, kMaxSphereContacts>;
using ContactVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxSphereContacts, 1>;
using CandidateVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxSphereCandidates, 1>;

}  // namespace

ForceSample evaluate_sphere_contact(const IntermediateRepresentation& envelope, const CondensedFemIr& ir,
                                    const PreparedFem& prepared, SphereWarmStart* warm_start,
                                    const Eigen::Vector3d& own_tool,
                                    std::span<const Eigen::Vector3d> remote_tools) noexcept {
  ForceSample sample;
  if (!own_tool.allFinite()) {
    sample.flags |= kNonFinite;
    return sample;
  }

  // The spheres: the own first, then the remote ones (a non-finite position holds nothing).
  std::array<SphereTool, kMaxUsers> tools;
  std::size_t tool_count = 1;
  tools[0] = {own_tool, envelope.tool_radius};
  for (std::size_t r = 0; r < ir.remotes.size() && r < remote_tools.size(); ++r) {
    if (tool_count == tools.size()) {
      sample.flags |= kTooManyRemotes;
      break;
    }
    tools[tool_count++] = {remote_tools[r], ir.remotes[r].tool_radius};
  }
  const std::span<const SphereTool> spheres(tools.data(), tool_count);

  // The candidates: every contact node, of the sphere nearest it.
  std::array<int, kMaxSphereCandidates> node{};
  std::array<SphereConstraint, kMaxSphereCandidates> constraint{};
  int m = 0;
  for (int i = 0; i < ir.row_node_count && i < kMaxSphereCandidates; ++i) {
    const auto candidate = sphere_constraint(ir.rest_positions.col(i), ir.fixed_axes[static_cast<std::size_t>(i)], spheres);
    if (!candidate) continue;
    node[static_cast<std::size_t>(m)] = i;
    constraint[static_cast<std::size_t>(m)] = *candidate;
    if (candidate->tool == 0 && candidate->gap < 0) {  // the own sphere holds it at rest
      sample.flags |= kInContact;
      sample.depth = std::max(sample.depth, -candidate->gap);
    }
    ++m;
  }
  const Eigen::Matrix3Xd& outside = prepared.sphere.outside_corners;
  for (Eigen::Index c = 0; c < outside.cols(); ++c)
    if ((outside.col(c) - own_tool).norm() < envelope.tool_radius) sample.flags |= kOutsidePatch;

  // Their clearances q = g + n . u0, from u0 over the free dofs.
  CandidateVector q(m);
  for (int i = 0; i < m; ++i) {
    const std::array<int, 3>& rows = prepared.dof_index[static_cast<std::size_t>(node[static_cast<std::size_t>(i)])];
    q[i] = constraint[static_cast<std::size_t>(i)].gap;
    for (int axis = 0; axis < 3; ++axis)
      if (rows[axis] >= 0) q[i] += constraint[static_cast<std::size_t>(i)].normal[axis] * prepared.free_displacement[rows[axis]];
  }
  // A_ij = n_i^T L~_ij n_j, formed only against the working set.
  const auto entry = [&](int i, int j) noexcept {
    const std::array<int, 3>& rows_i = prepared.dof_index[static_cast<std::size_t>(node[static_cast<std::size_t>(i)])];
    const std::array<int, 3>& rows_j = prepared.dof_index[static_cast<std::size_t>(node[static_cast<std::size_t>(j)])];
    const Eigen::Vector3d& n_i = constraint[static_cast<std::size_t>(i)].normal;
    const Eigen::Vector3d& n_j = constraint[static_cast<std::size_t>(j)].normal;
    double value = 0;
    for (int p = 0; p < 3; ++p) {
      if (rows_i[p] < 0) continue;
      for (int r = 0; r < 3; ++r)
        if (rows_j[r] >= 0) value += n_i[p] * prepared.compliance(rows_i[p], rows_j[r]) * n_j[r];
    }
    return value;
  };

  // Which touch, warm started from the last tick.
  std::array<std::uint8_t, kMaxSphereCandidates> active{};
  if (warm_start)
    for (int i = 0; i < m; ++i) active[static_cast<std::size_t>(i)] = warm_start->active(node[static_cast<std::size_t>(i)]);
  std::array<std::uint8_t, kMaxSphereCandidates> member_active{}, in_set{};
  std::array<int, kMaxSphereCandidates> members{}, order{};
  WorkingSetScratch<ContactMatrix, ContactVector> scratch{{}, {}, {}, {}, members, member_active, order, in_set};
  CandidateVector lambda(m);
  const std::span<std::uint8_t> active_span(active.data(), static_cast<std::size_t>(m));
  const WorkingSetSolveResult solved = solve_unilateral_over_candidates(
      q, entry, [](std::span<const int>) noexcept {}, kMaxSphereContacts, active_span, lambda, scratch, kSphereSolveWork);
  if (!solved.inner.solved) {
    sample.flags |= kContactUnresolved;
    return sample;
  }
  if (warm_start) warm_start->store(std::span<const int>(node.data(), static_cast<std::size_t>(m)), active_span);

  Eigen::Vector3d contact_force = Eigen::Vector3d::Zero();
  for (int i = 0; i < m; ++i)
    if (constraint[static_cast<std::size_t>(i)].tool == 0 && lambda[i] > 0) {
      contact_force += lambda[i] * constraint[static_cast<std::size_t>(i)].normal;
      sample.flags |= kInContact;  // pushed, held at rest or carried in
    }
  sample.force = -contact_force;
  limit_force(sample, true, envelope.force_limit);
  return sample;
}

}  // namespace cohaptic
