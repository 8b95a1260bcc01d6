#include "common/ir/separation_evaluation.h"

namespace cohaptic {

ForceSample step_separation_force(const SeparationPatch& patch, SeparationState& state,
                                  SeparationToolState& tool, const SeparationToolSettings& settings,
                                  const Eigen::Vector3d& tip, std::uint32_t buttons, double dt,
                                  double force_limit) noexcept {
  const SeparationToolSample tick =
      step_separation_tool(patch, state, tool, settings, tip, buttons, dt);
  ForceSample sample;
  sample.force = tick.contact.force;
  if (tick.contact.flags & kSeparationInContact) {
    sample.flags |= kInContact;
    sample.triangle = tool.contact.point.triangle;
    sample.depth = tick.contact.deflection.norm();
  }
  limit_force(sample, tip.allFinite() && !(tick.contact.flags & kSeparationNonFinite), force_limit);
  return sample;
}

}  // namespace cohaptic
