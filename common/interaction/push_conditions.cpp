#include "common/interaction/push_conditions.h"

#include <fmt/format.h>

#include "common/fem/static_solve.h"
#include "common/interaction/condensed_response.h"
#include "common/interaction/interaction_step.h"
#include "common/interaction/node_pairs.h"
#include "common/mass_spring/network_stiffness.h"
#include "common/util/error.h"

namespace cohaptic {

const char* back_condition_name(BackCondition condition) {
  switch (condition) {
    case BackCondition::free:
      return "free";
    case BackCondition::fixed:
      return "fixed";
    case BackCondition::on_behind:
      return "on_behind";
  }
  return "?";
}

namespace {

// A's stiffness with the backing's added on its nodes' blocks.
SparseMatrix backed_stiffness(const SparseMatrix& front, const LinearBacking& backing) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(front.nonZeros() + backing.stiffness.size()));
  for (int column = 0; column < front.outerSize(); ++column)
    for (SparseMatrix::InnerIterator it(front, column); it; ++it)
      entries.emplace_back(it.row(), it.col(), it.value());
  const auto count = static_cast<int>(backing.nodes.size());
  for (int i = 0; i < count; ++i)
    for (int j = 0; j < count; ++j)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          entries.emplace_back(3 * backing.nodes[static_cast<std::size_t>(i)] + r,
                               3 * backing.nodes[static_cast<std::size_t>(j)] + c,
                               backing.stiffness(3 * i + r, 3 * j + c));
  SparseMatrix sum(front.rows(), front.cols());
  sum.setFromTriplets(entries.begin(), entries.end());
  return sum;
}

// Each collision's backing force at A's displacement; the indices of those pulling A's
// node into B (against the polygon's outward normal).
std::vector<std::size_t> pulling(const std::vector<PolygonCollision>& collisions,
                                 const LinearBacking& backing,
                                 const Eigen::VectorXd& displacement) {
  const auto size = static_cast<Eigen::Index>(3 * backing.nodes.size());
  Eigen::VectorXd u(size), f(size);
  for (std::size_t k = 0; k < backing.nodes.size(); ++k)
    u.segment<3>(3 * static_cast<Eigen::Index>(k)) = displacement.segment<3>(3 * backing.nodes[k]);
  evaluate_linear_backing(backing, u, f);
  // Round-off of a node that neither presses nor pulls is not a pull.
  const double tolerance = 1e-12 * std::max(f.cwiseAbs().maxCoeff(), 1e-300);
  std::vector<std::size_t> pull;
  for (std::size_t k = 0; k < collisions.size(); ++k)
    if (f.segment<3>(3 * static_cast<Eigen::Index>(k)).dot(collisions[k].normal) < -tolerance)
      pull.push_back(k);
  return pull;
}

}  // namespace

std::vector<PushSample> push_front(const PushedFront& front, BackCondition condition,
                                   const BehindBody* behind, std::span<const double> depths) {
  if (condition == BackCondition::on_behind && behind == nullptr)
    throw Error("push_front: the condition on_behind needs the body behind");
  const SparseMatrix spring_stiffness = network_stiffness(front.rest_positions, front.springs);
  std::vector<AxisMask> fixed_axes = front.fixed_axes;
  if (condition == BackCondition::fixed)
    for (int node : front.back_face) fixed_axes[static_cast<std::size_t>(node)] = kAllAxes;
  const DofMap dofs = make_dof_map(fixed_axes);
  const int tool_dof = 3 * front.tool_node + front.push_axis;

  // On B: every free back node paired with B's surface; those that touch it collide.
  std::vector<PolygonCollision> collisions;
  if (condition == BackCondition::on_behind) {
    std::vector<int> back;
    for (int node : front.back_face)
      if (fixed_axes[static_cast<std::size_t>(node)] != kAllAxes) back.push_back(node);
    const NodePairList pairs = make_node_pairs(back, front.rest_positions,
                                               behind->body.surface.nodes, behind->body.mesh.nodes);
    collisions = find_polygon_collisions(
        pairs, {front.rest_positions, front.surface, behind->body.mesh.nodes, behind->surface,
                behind->body.dofs, behind->columns});
    if (collisions.empty())
      throw Error("push_front: no node of A's back face touches the body behind");
  }

  std::vector<PushSample> samples;
  samples.reserve(depths.size());
  for (double depth : depths) {
    PushSample sample;
    sample.depth = depth;
    sample.collisions = collisions;
    for (;;) {
      LinearBacking backing;
      SparseMatrix stiffness = spring_stiffness;
      if (condition == BackCondition::on_behind) {
        sample.forcible = forcible_displacement(sample.collisions, behind->body.dofs.fixed_axes);
        backing = build_linear_backing(
            sample.collisions, sample.forcible,
            condensed_stiffness(behind->columns, behind->body.dofs, sample.forcible.nodes),
            front.rest_positions);
        stiffness = backed_stiffness(spring_stiffness, backing);
      }
      // The tool holds its node: pushed along the axis, held across it.
      std::vector<PrescribedDisplacement> pushed;
      for (int axis = 0; axis < 3; ++axis)
        pushed.push_back({3 * front.tool_node + axis, axis == front.push_axis ? depth : 0.0});
      const StaticSolution solution = solve_static(stiffness, dofs, pushed);
      sample.displacement = solution.displacement;
      sample.force = solution.reaction[tool_dof];
      if (condition != BackCondition::on_behind) break;
      const std::vector<std::size_t> pull =
          pulling(sample.collisions, backing, sample.displacement);
      if (pull.empty()) break;
      if (pull.size() == sample.collisions.size())
        throw Error(
            fmt::format("push_front: B would pull every back node of A at depth {} m", depth));
      for (auto k = pull.rbegin(); k != pull.rend(); ++k)
        sample.collisions.erase(sample.collisions.begin() + static_cast<std::ptrdiff_t>(*k));
      sample.released += static_cast<int>(pull.size());
    }
    samples.push_back(std::move(sample));
  }
  return samples;
}

}  // namespace cohaptic
