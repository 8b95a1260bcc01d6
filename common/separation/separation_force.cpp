#include "common/separation/separation_force.h"

#include "common/separation/polynomial_fit.h"

namespace cohaptic {

FieldValue field_value(const SeparationPatch& patch, int node, int tool_node, FieldState state,
                       const Eigen::Vector3d& delta) noexcept {
  const double* block = patch.field(node, tool_node, state);
  const Eigen::Map<const Eigen::Matrix3d> frame(block);
  const Eigen::Vector3d local = frame.transpose() * delta;
  const int d = patch.degree;
  Eigen::Vector3d local_force;
  FieldValue value;
  for (int a = 0; a < 3; ++a) {
    const double* c = block + 9 + a * d;
    local_force[a] = polynomial_value(c, d, local[a]);
    value.energy += polynomial_integral(c, d, local[a]);
  }
  value.force = frame * local_force;
  return value;
}

FieldValue nodal_separation_field(const SeparationPatch& patch, int node, int tool_node,
                                  double local_separated, double global_separated,
                                  const Eigen::Vector3d& delta) noexcept {
  const double weights[kFieldStates] = {(1 - global_separated) * (1 - local_separated),
                                        (1 - global_separated) * local_separated, global_separated};
  FieldValue sum;
  for (int s = 0; s < kFieldStates; ++s) {
    if (weights[s] == 0) continue;
    const FieldValue v = field_value(patch, node, tool_node, static_cast<FieldState>(s), delta);
    sum.force += weights[s] * v.force;
    sum.energy += weights[s] * v.energy;
  }
  return sum;
}

ContactAreas contact_areas(const SeparationPatch& patch, const SeparationState& state,
                           int triangle) noexcept {
  ContactAreas areas;
  for (int k = 0; k < 3; ++k)
    areas.local_separated[k] = local_separated_share(patch, state, patch.triangles[triangle][k]);
  areas.global_separated = global_separated_share(patch, state);
  return areas;
}

FieldValue contact_field(const SeparationPatch& patch, const ContactPoint& contact,
                         const ContactAreas& areas, const Eigen::Vector3d& delta) noexcept {
  FieldValue sum;
  const Triangle& nodes = patch.triangles[contact.triangle];
  for (int k = 0; k < 3; ++k) {
    if (contact.weights[k] == 0) continue;
    for (int l = 0; l < 3; ++l) {
      const double w = contact.weights[k] * contact.tool_weights[l];
      if (w == 0) continue;
      const FieldValue v =
          nodal_separation_field(patch, nodes[k], contact.tool_nodes[l], areas.local_separated[k],
                                 areas.global_separated, delta);
      sum.force += w * v.force;
      sum.energy += w * v.energy;
    }
  }
  return sum;
}

}  // namespace cohaptic
