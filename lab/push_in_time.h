// The several-objects paper's pushing test in time, as the paper ran it (Sec. 3.2: 15 mm
// at 5 mm/s): the test's scene, varied for a condition (objects_push.h: push_scene), run
// through the server's own simulation (SceneSimulation at the scene's haptic rate: A's
// integrator with its spring dampers and node masses, B's interaction each step), with one
// frictionless point tool scripted along the push axis from the centre of A's front face.
// The tool couples to A as any tool couples to a mass-spring body (tool_coupling.h): the
// surface node it presses follows it, and it feels the mean of Eq. (5)'s force over each
// period. Pushed along the node's own line, the node is the one nearest the tool and the
// contact point stays on it, so the node's displacement is the tool's: the paper's
// prescribed displacement of the pushed node.
// Units: SI.
#pragma once

#include <vector>

#include "common/scene/scene.h"
#include "lab/objects_push.h"

namespace cohaptic {

struct PushInTimeOptions {
  double speed = 5e-3;   ///< [m/s]
  double depth = 15e-3;  ///< the push's end [m]
};

/// One server step of the push.
struct PushInTimeSample {
  double time = 0;   ///< [s]
  double depth = 0;  ///< the pushed node's mean displacement over the step's period [m]
  double force = 0;  ///< the tool's mean force along the push over that period [N]
};

/// The push of the pushing test's `scene` (push_layout) varied by `variation`, from rest, one
/// sample per server step after the first. Throws Error when the tool does not press A.
std::vector<PushInTimeSample> push_in_time(const Scene& scene, const PushVariation& variation,
                                           const PushInTimeOptions& options = {});

/// The slow limit of the same push without the body behind (conditions free and fixed):
/// A's nonlinear static equilibrium (network_equilibrium.h) with the pushed node held as
/// the tool holds it, at each of `depths` [m] in turn; the tool's force [N]. Throws Error
/// for on_behind.
std::vector<double> network_static_forces(const Scene& scene, const PushVariation& variation,
                                          const std::vector<double>& depths);

/// The force at each of `depths` [m], linearly interpolated between the samples around it.
std::vector<double> forces_at_depths(const std::vector<PushInTimeSample>& samples,
                                     const std::vector<double>& depths);

}  // namespace cohaptic
