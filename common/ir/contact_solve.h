// The contact forces of pressing tools on a condensed compliance: the core both the force
// evaluator (per tick, per user) and the simulation's state solve use.
//
// Given L~_ZZ, the compliance of the pressing tools' contact dofs Z with the boundary
// nodes held, and u0_Z, their displacement when unloaded:
//   node translation: u_Z = d of each dof's tool, f_Z = L~_ZZ^-1 (u_Z - u0_Z), and the
//     tool's force F_t = sum over its dofs of w_i f_i (the paper's eq. 5);
//   point constraint: f_Z = W lambda with W^T u_Z = d, (W^T L~_ZZ W) lambda = d - W^T u0_Z,
//     and F_t = lambda_t.
// Allocation-free: every matrix has a fixed maximum size (kMaxContactDofs). Units: m, N.
#pragma once

#include <Eigen/Core>
#include <span>

#include "common/kinds/contact_model.h"
#include "common/kinds/session_limits.h"

namespace cohaptic {

constexpr int kMaxContactDofs = 9 * kMaxUsers;

using SmallMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor,
                                  kMaxContactDofs, kMaxContactDofs>;
using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxContactDofs, 1>;

/// One contact dof: its tool, axis and the area coordinate of its node in that tool's triangle.
struct ContactDof {
  int tool = 0;
  int axis = 0;
  double weight = 0;
};

/// Fills `nodal_forces` (per dof, the tool's force on the node) and `tool_forces` (the
/// force each tool applies to the object). Returns false if a system was not positive
/// definite (the outputs are then meaningless).
bool solve_contact_forces(ContactModel model, const SmallMatrix& compliance,
                          const SmallVector& free_displacement, std::span<const ContactDof> dofs,
                          std::span<const Eigen::Vector3d> tool_displacement,
                          SmallVector& nodal_forces,
                          std::span<Eigen::Vector3d> tool_forces) noexcept;

}  // namespace cohaptic
