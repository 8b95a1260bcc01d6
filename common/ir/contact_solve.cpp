#include "common/ir/contact_solve.h"

#include <Eigen/Cholesky>

namespace cohaptic {

bool solve_contact_forces(ContactModel model, const SmallMatrix& compliance,
                          const SmallVector& free_displacement, std::span<const ContactDof> dofs,
                          std::span<const Eigen::Vector3d> tool_displacement,
                          SmallVector& nodal_forces,
                          std::span<Eigen::Vector3d> tool_forces) noexcept {
  const auto z = static_cast<Eigen::Index>(dofs.size());
  const auto tools = static_cast<Eigen::Index>(tool_displacement.size());
  for (Eigen::Vector3d& f : tool_forces) f.setZero();
  if (model == ContactModel::node_translation) {
    SmallVector rhs(z);
    for (Eigen::Index i = 0; i < z; ++i)
      rhs[i] = tool_displacement[dofs[i].tool][dofs[i].axis] - free_displacement[i];
    const Eigen::LLT<SmallMatrix> llt(compliance);
    nodal_forces = llt.solve(rhs);
    for (Eigen::Index i = 0; i < z; ++i)
      tool_forces[dofs[i].tool][dofs[i].axis] += dofs[i].weight * nodal_forces[i];
    return llt.info() == Eigen::Success;
  }
  // W: dof i carries w_i of its tool's force component along its axis.
  SmallMatrix w = SmallMatrix::Zero(z, 3 * tools);
  for (Eigen::Index i = 0; i < z; ++i) w(i, 3 * dofs[i].tool + dofs[i].axis) = dofs[i].weight;
  const SmallMatrix a = w.transpose() * compliance * w;
  SmallVector rhs(3 * tools);
  for (Eigen::Index t = 0; t < tools; ++t) rhs.segment<3>(3 * t) = tool_displacement[t];
  rhs -= w.transpose() * free_displacement;
  const Eigen::LLT<SmallMatrix> llt(a);
  const SmallVector lambda = llt.solve(rhs);
  nodal_forces = w * lambda;
  for (Eigen::Index t = 0; t < tools; ++t) tool_forces[t] = lambda.segment<3>(3 * t);
  return llt.info() == Eigen::Success;
}

}  // namespace cohaptic
