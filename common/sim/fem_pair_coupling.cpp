#include "common/sim/fem_pair_coupling.h"

#include <Eigen/Cholesky>
#include <Eigen/SparseCore>
#include <cstdint>
#include <limits>
#include <vector>

#include "common/contact/unilateral_contact_solve.h"
#include "common/interaction/compliance_backing.h"

namespace cohaptic {
namespace {

// The 3 dofs of each collision's active node, collision-major.
std::vector<int> pair_active_dofs(std::span<const PolygonCollision> collisions) {
  std::vector<int> dofs;
  for (const PolygonCollision& collision : collisions)
    for (int axis = 0; axis < 3; ++axis) dofs.push_back(3 * collision.active + axis);
  return dofs;
}

// N: 3|collisions| x |collisions|, column j holding n_j in rows 3j..3j+2. Sparse: a dense N
// made N^T L N cost O(m^3) (3 ms a step for A's 117 candidates in fem_pair.yaml), sparse O(m^2).
Eigen::SparseMatrix<double> pair_normal_matrix(std::span<const PolygonCollision> collisions) {
  const auto count = static_cast<Eigen::Index>(collisions.size());
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index j = 0; j < count; ++j)
    for (int axis = 0; axis < 3; ++axis)
      entries.emplace_back(3 * j + axis, j, collisions[static_cast<std::size_t>(j)].normal[axis]);
  Eigen::SparseMatrix<double> normals(3 * count, count);
  normals.setFromTriplets(entries.begin(), entries.end());
  return normals;
}

}  // namespace

FemPairContact solve_fem_pair_contact(std::span<const PolygonCollision> collisions,
                                      ComplianceColumns& front_columns,
                                      std::span<const int> front_held_dofs,
                                      ComplianceColumns& behind_columns) {
  const auto count = static_cast<Eigen::Index>(collisions.size());
  FemPairContact contact;
  contact.behind_compliance = target_normal_compliance(collisions, behind_columns);
  const std::vector<int> active_dofs = pair_active_dofs(collisions);
  const Eigen::SparseMatrix<double> normals = pair_normal_matrix(collisions);
  const Eigen::MatrixXd block_times_normals =
      front_columns.dof_block(active_dofs, active_dofs) * normals;
  contact.front_compliance = normals.transpose() * block_times_normals;
  // The held dofs stay where they are: the Schur complement of L_HH.
  Eigen::MatrixXd held_response;  // L_HH^-1 L_HP N
  if (!front_held_dofs.empty()) {
    const Eigen::LLT<Eigen::MatrixXd> held(
        front_columns.dof_block(front_held_dofs, front_held_dofs));
    const Eigen::MatrixXd coupling =
        Eigen::MatrixXd(front_columns.dof_block(front_held_dofs, active_dofs) * normals);  // L_HP N
    held_response = held.solve(coupling);
    contact.front_compliance -= coupling.transpose() * held_response;
  }
  contact.front_compliance = (contact.front_compliance + contact.front_compliance.transpose()) / 2;

  contact.free_gaps.resize(count);
  for (Eigen::Index i = 0; i < count; ++i) {
    const PolygonCollision& collision = collisions[static_cast<std::size_t>(i)];
    contact.free_gaps[i] = collision.gap.dot(collision.normal);
  }
  const Eigen::MatrixXd sum = contact.front_compliance + contact.behind_compliance;
  std::vector<std::uint8_t> active(static_cast<std::size_t>(count));
  for (Eigen::Index i = 0; i < count; ++i)
    active[static_cast<std::size_t>(i)] = contact.free_gaps[i] < 0;
  contact.pushes = Eigen::VectorXd::Zero(count);
  Eigen::MatrixXd factor(count, count);
  std::vector<int> order(static_cast<std::size_t>(count));
  contact.solved = solve_unilateral_contact(sum, contact.free_gaps, active, contact.pushes, factor,
                                            order, std::numeric_limits<double>::infinity())
                       .solved;
  contact.gaps = sum * contact.pushes + contact.free_gaps;
  contact.held_force_change = front_held_dofs.empty()
                                  ? Eigen::VectorXd()
                                  : Eigen::VectorXd(-held_response * contact.pushes);
  return contact;
}

Eigen::VectorXd behind_pair_displacement(std::span<const PolygonCollision> collisions,
                                         const Eigen::Ref<const Eigen::VectorXd>& pushes,
                                         ComplianceColumns& behind_columns) {
  Eigen::VectorXd displacement =
      Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(behind_columns.row_nodes().size()));
  for (std::size_t j = 0; j < collisions.size(); ++j) {
    const PolygonCollision& collision = collisions[j];
    const double push = pushes[static_cast<Eigen::Index>(j)];
    if (push == 0) continue;
    for (int b = 0; b < 3; ++b)
      displacement -= behind_columns.column(collision.polygon[b]) *
                      (collision.weights[b] * push * collision.normal);
  }
  return displacement;
}

}  // namespace cohaptic
