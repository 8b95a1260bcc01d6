#include "common/separation/separation_tool.h"

#include <cmath>
#include <limits>

#include "common/contact/closest_point_on_triangle.h"

namespace cohaptic {

ContactPoint nearest_patch_point(const SeparationPatch& patch, const Eigen::Vector3d& p,
                                 double& distance) noexcept {
  ContactPoint point;
  double best = std::numeric_limits<double>::infinity();
  for (int t = 0; t < patch.triangle_count(); ++t) {
    const Triangle& tri = patch.triangles[t];
    const TriangleClosestPoint q = closest_point_on_triangle(
        p, patch.positions.col(tri[0]), patch.positions.col(tri[1]), patch.positions.col(tri[2]));
    const double d2 = (p - q.point).squaredNorm();
    if (d2 < best) {
      best = d2;
      point.triangle = t;
      point.weights = q.weights;
    }
  }
  distance = std::sqrt(best);
  return point;
}

SeparationToolSample step_separation_tool(const SeparationPatch& patch, SeparationState& state,
                                          SeparationToolState& tool,
                                          const SeparationToolSettings& settings,
                                          const Eigen::Vector3d& tip, std::uint32_t buttons,
                                          double dt) noexcept {
  SeparationToolSample sample;
  const bool firing = settings.laser && (buttons & kLaserFireButton) != 0;
  const bool pushes = settings.contact == ContactMode::push;
  const bool jaws = !pushes && (buttons & jaw_button(settings)) != 0 && !firing;
  const bool engaged = pushes ? !firing : jaws;
  if (!engaged) tool.contact.mode = ContactMode::none;
  sample.laser = step_laser(patch, state, tool.fibre, tip, firing, dt);
  const bool may_touch = pushes || !tool.jaws_closed;  // jaws grasp only as they close
  if (engaged && may_touch && tool.contact.mode == ContactMode::none && tip.allFinite()) {
    const ContactPoint point = nearest_patch_point(patch, tip, sample.distance);
    if (sample.distance <= settings.grasp_reach)
      tool.contact = begin_contact(patch, settings.contact, point, tip);
  }
  tool.jaws_closed = jaws;
  if (tool.contact.mode != ContactMode::none)
    sample.contact = step_contact(patch, state, tool.contact, tip);
  return sample;
}

}  // namespace cohaptic
