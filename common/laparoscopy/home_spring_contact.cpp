#include "common/laparoscopy/home_spring_contact.h"

#include "common/laparoscopy/home_spring_force.h"

namespace cohaptic {

PreparedHomeSpringPatch prepare_home_spring_patch(HomeSpringPatch patch) {
  validate_home_spring_patch(patch);
  AabbTree tree(patch.rest_positions, patch.triangles);
  return PreparedHomeSpringPatch{std::move(patch), std::move(tree)};
}

HomeSpringContact evaluate_home_spring(const PreparedHomeSpringPatch& prepared,
                                       const Eigen::Vector3d& tool) noexcept {
  const HomeSpringPatch& patch = prepared.patch;
  HomeSpringContact contact;
  if (!tool.allFinite()) return contact;
  if (patch.grasp.active()) {
    contact.vertex = patch.grasp.vertex;
    contact.contact_point = patch.rest_positions.col(contact.vertex);
    contact.displacement = tool - patch.grasp.tool_at_grasp;
  } else {
    const AabbCrossing hit = prepared.rest_surface.first_crossing(patch.trocar_pivot, tool);
    if (hit.triangle < 0) return contact;
    const Triangle& tri = patch.triangles[static_cast<std::size_t>(hit.triangle)];
    contact.contact_point = patch.trocar_pivot + hit.crossing.t * (tool - patch.trocar_pivot);
    double nearest2 = 0;
    for (const int v : tri) {
      const double d2 = (patch.rest_positions.col(v) - contact.contact_point).squaredNorm();
      if (contact.vertex < 0 || d2 < nearest2) {
        contact.vertex = v;
        nearest2 = d2;
      }
    }
    contact.displacement = tool - contact.contact_point;
  }
  contact.touching = true;
  contact.force = -home_spring_load(patch, contact.vertex, contact.displacement);
  return contact;
}

}  // namespace cohaptic
