// The state solve of every linear elastic body of a scene simulation, once per display or
// live-view frame: what their drawings are computed from. A solve touches the condensation's
// caches, so the replay repeats it at the same steps (the step record's display_frame) to
// stay bit for bit; the live loop and the replay both call this. Units: SI (StateSolution's).
#pragma once

#include <optional>
#include <vector>

#include "common/sim/scene_simulation.h"

namespace cohaptic {

/// Per body of `simulation`: its StateSolution when it is linear elastic, nullopt otherwise.
std::vector<std::optional<StateSolution>> solve_elastic_states(SceneSimulation& simulation);

}  // namespace cohaptic
