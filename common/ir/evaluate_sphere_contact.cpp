#include "common/ir/evaluate_sphere_contact.h"

#include <algorithm>
#include <array>
#include <limits>

#include "common/contact/sphere_contact.h"

namespace cohaptic {

ForceSample evaluate_sphere_contact(const IntermediateRepresentation& envelope,
                                    const CondensedFemIr& ir, const PreparedFem& prepared,
                                    SphereContactState* state, const Eigen::Vector3d& own_tool,
                                    std::span<const Eigen::Vector3d> remote_tools) noexcept {
  ForceSample sample;
  const int m = ir.row_node_count;
  if (!own_tool.allFinite() || !state || !ir.sphere || state->clearance.size() != m ||
      state->solve.capacity() != m) {
    sample.flags |= kNonFinite;
    return sample;
  }
  const SphereContactIr& sphere = *ir.sphere;

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

  // Each row node's clearance from the sphere with the least gap along its normal, or from
  // the rigid obstacle that holds it (its gap does not depend on the tools).
  const bool obstacles = sphere.obstacle_gaps.size() == m;
  for (int i = 0; i < m; ++i) {
    double gap = std::numeric_limits<double>::infinity();
    std::int8_t holder = -1;
    if (obstacles && sphere.obstacle_gaps[i] < gap)
      gap = sphere.obstacle_gaps[i];
    else if (sphere.normals.col(i).squaredNorm() > 0)
      for (std::size_t t = 0; t < tool_count; ++t)
        if (const double g = sphere_gap(ir.rest_positions.col(i), sphere.normals.col(i), tools[t]);
            g < gap) {
          gap = g;
          holder = static_cast<std::int8_t>(t);
        }
    state->holder[static_cast<std::size_t>(i)] = holder;
    state->clearance[i] = gap + sphere.free_clearance[i];
    if (holder == 0 && gap < 0) {  // the own sphere holds it at rest
      sample.flags |= kInContact;
      sample.depth = std::max(sample.depth, -gap);
    }
  }
  const Eigen::Matrix3Xd& outside = prepared.sphere.outside_corners;
  for (Eigen::Index c = 0; c < outside.cols(); ++c)
    if ((outside.col(c) - own_tool).norm() < envelope.tool_radius) sample.flags |= kOutsidePatch;

  const UnilateralSolveResult solved =
      state->solve.solve(sphere.normal_compliance, state->clearance,
                         prepared.sphere.nonnegative_rows, state->work_budget);
  if (!solved.solved) {
    sample.flags |= kContactUnresolved;
    return sample;
  }
  Eigen::Vector3d contact_force = Eigen::Vector3d::Zero();
  const std::span<const int> members = state->solve.members();
  for (int p = 0; p < static_cast<int>(members.size()); ++p) {
    const int i = members[static_cast<std::size_t>(p)];
    const double push = state->solve.member_push(p);
    if (state->holder[static_cast<std::size_t>(i)] != 0 || !(push > 0)) continue;
    contact_force += push * sphere.normals.col(i);
    sample.flags |= kInContact;  // pushed, held at rest or carried in
  }
  sample.force = -contact_force;
  limit_force(sample, true, envelope.force_limit);
  return sample;
}

}  // namespace cohaptic
