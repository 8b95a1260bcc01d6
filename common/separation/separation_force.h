// The separation force at a contact: the paper's Eq. 2 at each node, interpolated over the
// body triangle and the tool triangle (Algorithm V.2).
//
// With delta = x - c the deflection (tool contact point x, body contact point c):
//   F_ij(delta) = A(S) [A(R_i) F_ij + A(R-bar_i) F-bar_ij](delta) + A(S-bar) F^e_ij(delta)
//   F(delta)    = sum_i alpha_i(c) sum_j beta_j(x) F_ij(delta)
// alpha are c's area coordinates on its patch triangle, beta x's on the tool triangle.
// The weights of the three fields sum to one at every node. Each field is a gradient (see
// separation_fields.h), so for fixed areas and contact points F is the gradient of the
// potential U(delta), returned with it: U is the elastic energy the fields store, the
// term an energy balance needs. F is the force on the pulled body [N]; U in J.
// Everything here is noexcept and allocates nothing.
#pragma once

#include <Eigen/Core>
#include <array>

#include "common/separation/separation_patch.h"
#include "common/separation/separation_state.h"

namespace cohaptic {

struct FieldValue {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< [N] on the pulled body
  double energy = 0;                                ///< [J]
};

/// One precomputed field at deflection `delta` [m].
FieldValue field_value(const SeparationPatch& patch, int node, int tool_node, FieldState state,
                       const Eigen::Vector3d& delta) noexcept;

/// Eq. 2 at one node and tool node, for the separated shares A(R-bar_i) and A(S-bar).
FieldValue nodal_separation_field(const SeparationPatch& patch, int node, int tool_node,
                                  double local_separated, double global_separated,
                                  const Eigen::Vector3d& delta) noexcept;

/// Where a tool touches the patch: c on a patch triangle and x on a tool triangle.
struct ContactPoint {
  int triangle = -1;                                  ///< patch triangle of c
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();  ///< alpha: c's area coordinates
  std::array<int, 3> tool_nodes{0, 0, 0};  ///< tool triangle (repeat a node for a point tool)
  Eigen::Vector3d tool_weights{1, 0, 0};   ///< beta: x's area coordinates
};

/// The separated shares the contact's force depends on: A(R-bar) of the contact
/// triangle's three nodes and A(S-bar).
struct ContactAreas {
  std::array<double, 3> local_separated{0, 0, 0};
  double global_separated = 0;
};

ContactAreas contact_areas(const SeparationPatch& patch, const SeparationState& state,
                           int triangle) noexcept;

/// Algorithm V.2's interpolated force and its potential.
FieldValue contact_field(const SeparationPatch& patch, const ContactPoint& contact,
                         const ContactAreas& areas, const Eigen::Vector3d& delta) noexcept;

}  // namespace cohaptic
