// `cohaptic-lab tradeoff` on a laparoscopy tissue (`model: home_spring`): the home-spring
// model's row, to stand beside its FEM twin's (the same tissue as a linear elastic body,
// --reference-scene) on the same pokes, both against the twin's full FEM solve.
//
// The workload runs through the server's HomeSpringSimulation stepped every simulation
// period (instrument pokes: no buttons, so forceps poke as a probe does), each user's
// client evaluating its latest IR (evaluate_force, the haptic loop's function) at the
// scene's haptic rate and holding the force in between. Its "own model" error is against
// the same model solved at every sample (a second simulation stepped at the comparison
// rate): what the IR pipeline costs, the model aside. Costs as the FEM rows have them
// (precompute: building the body; "M~": the patch extraction of the steps that rebuilt
// IRs). Units as the column names say.
#pragma once

#include <vector>

#include "common/haptics/trajectory.h"
#include "common/scene/scene.h"
#include "lab/tradeoff.h"

namespace cohaptic {

/// The row "model home_spring". `scene`'s only object must be home_spring (throws Error
/// otherwise); `per_step` and `per_tick` are the reference's samples per simulation step
/// and per haptic tick.
TradeoffRow run_home_spring_setting(const Scene& scene, const std::vector<Trajectory>& motions,
                                    const ReferenceTrace& reference, int per_step, int per_tick);

}  // namespace cohaptic
