#include "support/fem_pair_rig.h"

#include <Eigen/LU>
#include <cmath>
#include <optional>

#include "common/fem/static_solve.h"
#include "common/interaction/node_polygon_collision.h"

namespace cohaptic::testing {
namespace {

// The node of A's front face (least x) nearest the face's centre.
int fem_pair_tool_node(const ElasticBody& front) {
  const double front_x = front.mesh.nodes.row(0).minCoeff();
  const Eigen::Vector3d centre =
      (front.mesh.nodes.rowwise().minCoeff() + front.mesh.nodes.rowwise().maxCoeff()) / 2;
  int best = -1;
  for (int node : front.surface.nodes) {
    const Eigen::Vector3d x = front.mesh.nodes.col(node);
    if (x.x() > front_x + 1e-9) continue;
    if (best < 0 || (x - centre).tail<2>().norm() <
                        (front.mesh.nodes.col(best) - centre).tail<2>().norm() - 1e-12)
      best = node;
  }
  return best;
}

PairedBoxesOptions fem_pair_options(double gap_mm) {
  PairedBoxesOptions options;
  options.gap_mm = gap_mm;
  return options;
}

}  // namespace

std::vector<int> node_dofs(int node) { return {3 * node, 3 * node + 1, 3 * node + 2}; }

FreePush push_without_behind(const ElasticBody& front, double depth,
                             const std::vector<int>& also_held) {
  FreePush push;
  push.tool_dofs = node_dofs(fem_pair_tool_node(front));
  std::vector<int> prescribed = push.tool_dofs;
  prescribed.insert(prescribed.end(), also_held.begin(), also_held.end());
  Eigen::VectorXd values = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(prescribed.size()));
  values[0] = depth;
  push.tool_values = values.head(3);
  const StaticSolution solution =
      ConstrainedStaticSolver(front.stiffness, front.dofs, prescribed).solve(values);
  push.displacement = solution.displacement;
  for (int a = 0; a < 3; ++a)
    push.tool_force[a] = solution.reaction[push.tool_dofs[static_cast<std::size_t>(a)]];
  return push;
}

std::vector<PolygonCollision> back_face_candidates(const PairedBoxesRig& rig,
                                                   const Eigen::VectorXd& displacement) {
  std::vector<PolygonCollision> collisions;
  for (int node : rig.front_face) {
    const Eigen::Vector3d point =
        rig.front.mesh.nodes.col(node) + displacement.segment<3>(3 * node);
    int nearest = -1;
    for (int b : rig.behind.surface.nodes)
      if (nearest < 0 || (rig.behind.mesh.nodes.col(b) - point).norm() <
                             (rig.behind.mesh.nodes.col(nearest) - point).norm())
        nearest = b;
    const std::optional<PolygonTarget> target =
        detailed_collision_test(point, nearest, rig.behind.mesh.nodes, rig.behind_surface);
    if (!target || (point - target->point).dot(target->normal) > kFemPairReach) continue;
    PolygonCollision collision;
    collision.active = node;
    collision.polygon = rig.behind_surface.triangles[static_cast<std::size_t>(target->triangle)];
    collision.weights = target->weights;
    collision.target = target->point;
    collision.gap = point - target->point;
    collision.normal = target->normal;
    collisions.push_back(collision);
  }
  return collisions;
}

CoupledPush::CoupledPush(double gap_mm, double depth)
    : rig(fem_pair_options(gap_mm)),
      free(push_without_behind(rig.front, depth)),
      collisions(back_face_candidates(rig, free.displacement)),
      front_columns(std::make_unique<ComplianceColumns>(rig.front.free_factor, rig.front.dofs,
                                                        rig.front.surface.nodes)),
      contact(solve_fem_pair_contact(collisions, *front_columns, free.tool_dofs,
                                     *rig.behind_columns)) {}

PushingSupport pushing_support(const CoupledPush& push) {
  std::vector<Eigen::Index> set;
  for (Eigen::Index j = 0; j < push.contact.pushes.size(); ++j)
    if (push.contact.pushes[j] > 0) set.push_back(j);
  const auto count = static_cast<Eigen::Index>(set.size());
  PushingSupport support;
  support.normals.resize(3, count);
  support.compliance.resize(count, count);
  for (Eigen::Index a = 0; a < count; ++a) {
    const PolygonCollision& collision =
        push.collisions[static_cast<std::size_t>(set[static_cast<std::size_t>(a)])];
    support.nodes.push_back(collision.active);
    support.normals.col(a) = collision.normal;
    for (Eigen::Index b = 0; b < count; ++b)
      support.compliance(a, b) = push.contact.behind_compliance(set[static_cast<std::size_t>(a)],
                                                                set[static_cast<std::size_t>(b)]);
  }
  return support;
}

std::vector<int> tool_neighbourhood(const CoupledPush& push) {
  const ElasticBody& a = push.rig.front;
  const int tool = push.free.tool_dofs[0] / 3;
  std::vector<int> nodes{tool};
  for (int node : a.surface.nodes)
    if (node != tool && std::abs(a.mesh.nodes(0, node) - a.mesh.nodes(0, tool)) < 1e-9 &&
        (a.mesh.nodes.col(node) - a.mesh.nodes.col(tool)).norm() < 0.03)
      nodes.push_back(node);
  return nodes;
}

SparseMatrix stiffness_with_support(const ElasticBody& a, const std::vector<int>& nodes,
                                    const Eigen::Matrix3Xd& normals,
                                    const Eigen::MatrixXd& support) {
  std::vector<Eigen::Triplet<double>> entries;
  const SparseMatrix k_ff = restrict_to_dofs(a.stiffness, a.dofs.free_dofs);
  for (int outer = 0; outer < k_ff.outerSize(); ++outer)
    for (SparseMatrix::InnerIterator it(k_ff, outer); it; ++it)
      entries.emplace_back(it.row(), it.col(), it.value());
  const Eigen::MatrixXd springs = support.inverse();
  const auto count = static_cast<Eigen::Index>(nodes.size());
  for (Eigen::Index i = 0; i < count; ++i)
    for (Eigen::Index j = 0; j < count; ++j)
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q) {
          const int row =
              a.dofs
                  .free_index[static_cast<std::size_t>(3 * nodes[static_cast<std::size_t>(i)] + p)];
          const int col =
              a.dofs
                  .free_index[static_cast<std::size_t>(3 * nodes[static_cast<std::size_t>(j)] + q)];
          if (row >= 0 && col >= 0)
            entries.emplace_back(row, col, normals(p, i) * springs(i, j) * normals(q, j));
        }
  SparseMatrix with_springs(k_ff.rows(), k_ff.cols());
  with_springs.setFromTriplets(entries.begin(), entries.end());
  return with_springs;
}

}  // namespace cohaptic::testing
