#include "common/model/sphere_contact_reference.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include "common/contact/obstacle_constraints.h"
#include "common/contact/working_set_contact_solve.h"
#include "common/util/error.h"

namespace cohaptic {

std::vector<int> SphereContactSolution::contact_nodes() const {
  std::vector<int> nodes;
  for (std::size_t i = 0; i < candidates.size(); ++i)
    if (pushes[static_cast<Eigen::Index>(i)] > 0) nodes.push_back(candidates[i]);
  return nodes;
}

SphereContactReference::SphereContactReference(const ElasticBody& body,
                                               std::vector<SphereConstraint> obstacles)
    : body_(body),
      obstacles_(std::move(obstacles)),
      candidates_(triangle_nodes(body.surface, body.touchable_triangles)),
      candidate_row_(static_cast<std::size_t>(body.mesh.node_count()), -1) {
  for (std::size_t node = 0; node < obstacles_.size(); ++node)
    if (obstacles_[node].obstacle >= 0) candidates_.push_back(static_cast<int>(node));
  std::sort(candidates_.begin(), candidates_.end());
  candidates_.erase(std::unique(candidates_.begin(), candidates_.end()), candidates_.end());
  for (int node : candidates_) {
    candidate_row_[static_cast<std::size_t>(node)] = static_cast<int>(row_dofs_.size());
    for (int axis = 0; axis < 3; ++axis) row_dofs_.push_back(3 * node + axis);
  }
}

SphereContactReference::~SphereContactReference() = default;

void SphereContactReference::factor_for(const HeldNodes& held) {
  if (solver_ && held.nodes == held_key_) return;
  std::vector<int> prescribed;
  for (int node : held.nodes)
    for (int axis = 0; axis < 3; ++axis)
      if (!body_.dofs.is_fixed(node, axis)) prescribed.push_back(3 * node + axis);
  solver_ =
      std::make_unique<ConstrainedStaticSolver>(body_.stiffness, body_.dofs, std::move(prescribed));
  held_key_ = held.nodes;
  columns_.clear();
  ++factorisations_;
}

void SphereContactReference::compute_columns(const std::vector<int>& nodes) {
  std::vector<int> load_dofs;
  for (int node : nodes)
    if (!columns_.count(node))
      for (int axis = 0; axis < 3; ++axis) load_dofs.push_back(3 * node + axis);
  if (load_dofs.empty()) return;
  const Eigen::MatrixXd block = solver_->compliance_block(row_dofs_, load_dofs);
  for (std::size_t c = 0; c < load_dofs.size(); c += 3)
    columns_.emplace(load_dofs[c] / 3, block.middleCols(static_cast<Eigen::Index>(c), 3));
}

const Eigen::MatrixXd& SphereContactReference::columns_of(int node) { return columns_.at(node); }

SphereContactSolution SphereContactReference::solve(const std::vector<PressedTool>& tools,
                                                    const HeldNodes& held,
                                                    Eigen::VectorXd* displacement) {
  std::vector<SphereTool> spheres;
  for (std::size_t t = 0; t < tools.size(); ++t) {
    if (!(tools[t].radius > 0))
      throw Error(fmt::format(
          "sphere contact: tool {} is a point (radius {}); the sphere model needs spheres", t + 1,
          tools[t].radius));
    spheres.push_back({tools[t].position, tools[t].radius});
  }
  factor_for(held);

  std::vector<bool> is_held(static_cast<std::size_t>(body_.mesh.node_count()), false);
  for (int node : held.nodes) is_held[static_cast<std::size_t>(node)] = true;
  SphereCandidates candidates;
  for (int node : candidates_)
    if (!is_held[static_cast<std::size_t>(node)])
      if (const auto constraint =
              node_constraint(body_.mesh.nodes.col(node), body_.contact_normals.col(node),
                              body_.dofs.fixed_axes[static_cast<std::size_t>(node)], spheres,
                              obstacle_at(obstacles_, node))) {
        candidates.nodes.push_back(node);
        candidates.constraints.push_back(*constraint);
      }

  SphereContactSolution solution;
  solution.candidates = candidates.nodes;
  solution.constraints = candidates.constraints;
  solution.reactions.assign(tools.size(), Eigen::Vector3d::Zero());
  const auto m = static_cast<Eigen::Index>(candidates.nodes.size());
  solution.pushes = Eigen::VectorXd::Zero(m);

  // u0: the displacement under the held nodes' displacements alone.
  std::vector<double> values;
  for (std::size_t h = 0; h < held.nodes.size(); ++h)
    for (int axis = 0; axis < 3; ++axis)
      if (!body_.dofs.is_fixed(held.nodes[h], axis)) values.push_back(held.displacement[h][axis]);
  const Eigen::Map<const Eigen::VectorXd> held_values(values.data(),
                                                      static_cast<Eigen::Index>(values.size()));
  Eigen::VectorXd u0 = Eigen::VectorXd::Zero(3 * body_.mesh.node_count());
  if (!held.nodes.empty() || (displacement && m == 0))
    u0 = solver_->solve(held_values).displacement;
  if (m == 0) {
    if (displacement) *displacement = u0;
    return solution;
  }
  Eigen::VectorXd q(m);
  for (Eigen::Index j = 0; j < m; ++j) {
    const SphereConstraint& c = candidates.constraints[static_cast<std::size_t>(j)];
    q[j] = c.gap + c.normal.dot(u0.segment<3>(3 * candidates.nodes[static_cast<std::size_t>(j)]));
  }

  // Which touch: the working set over every candidate, columns only for its members.
  const auto entry = [&](int i, int j) {
    const Eigen::MatrixXd& column = columns_of(candidates.nodes[static_cast<std::size_t>(j)]);
    const int row =
        candidate_row_[static_cast<std::size_t>(candidates.nodes[static_cast<std::size_t>(i)])];
    const Eigen::Vector3d moved =
        column.middleRows<3>(row) * candidates.constraints[static_cast<std::size_t>(j)].normal;
    return candidates.constraints[static_cast<std::size_t>(i)].normal.dot(moved);
  };
  const auto prepare_columns = [&](std::span<const int> set) {
    std::vector<int> nodes;
    for (int i : set) nodes.push_back(candidates.nodes[static_cast<std::size_t>(i)]);
    compute_columns(nodes);
  };
  std::vector<std::uint8_t> active(static_cast<std::size_t>(m), 0), member_active(active.size()),
      in_set(active.size());
  std::vector<int> members(active.size()), order(active.size());
  WorkingSetScratch<Eigen::MatrixXd, Eigen::VectorXd> scratch{
      {}, {}, {}, {}, members, member_active, order, in_set};
  const WorkingSetSolveResult result = solve_unilateral_over_candidates(
      q, entry, prepare_columns, static_cast<int>(m), active, solution.pushes, scratch,
      std::numeric_limits<double>::infinity());
  if (!result.inner.solved)
    throw NumericalError(
        "sphere contact: the candidates' normal compliance is not positive definite");
  for (Eigen::Index i = 0; i < m; ++i) {
    const SphereConstraint& c = candidates.constraints[static_cast<std::size_t>(i)];
    if (c.tool >= 0)
      solution.reactions[static_cast<std::size_t>(c.tool)] -= solution.pushes[i] * c.normal;
  }
  if (displacement) {
    Eigen::VectorXd loads = Eigen::VectorXd::Zero(3 * body_.mesh.node_count());
    for (Eigen::Index i = 0; i < m; ++i)
      loads.segment<3>(3 * candidates.nodes[static_cast<std::size_t>(i)]) +=
          solution.pushes[i] * candidates.constraints[static_cast<std::size_t>(i)].normal;
    *displacement = solver_->solve(held_values, loads).displacement;
  }
  return solution;
}

SphereContactSolution sphere_reactions_reference(const ElasticBody& body,
                                                 const std::vector<PressedTool>& tools,
                                                 const HeldNodes& held,
                                                 Eigen::VectorXd* displacement,
                                                 std::vector<SphereConstraint> obstacles) {
  return SphereContactReference(body, std::move(obstacles)).solve(tools, held, displacement);
}

}  // namespace cohaptic
