// The separation body's haptic tick as a ForceSample: the instrument stepped on a
// separated state (step_separation_tool), its force on the hand limited like every body's
// (limit_force). The client's evaluate_force and the server's authoritative step both call
// this one function, so that the same inputs give the same force bit for bit.
// noexcept, no allocation. Units: m, s, N.
#pragma once

#include "common/ir/evaluate_force.h"

namespace cohaptic {

ForceSample step_separation_force(const SeparationPatch& patch, SeparationState& state,
                                  SeparationToolState& tool, const SeparationToolSettings& settings,
                                  const Eigen::Vector3d& tip, std::uint32_t buttons, double dt,
                                  double force_limit) noexcept;

}  // namespace cohaptic
