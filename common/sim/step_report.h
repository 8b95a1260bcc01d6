// StepReport: what one step of a body's simulation did, and summed over the scene's bodies
// (SceneSimulation). Times in ms.
#pragma once

#include <cstddef>

namespace cohaptic {

struct StepReport {
  bool rebuilt =
      false;  ///< new IRs were built this step (a set changed, or a dynamic body's IR was due)
  bool recomputed = false;   ///< M~ was computed this step (rebuilt, or naive_every_step)
  double rebuild_ms = 0;     ///< time to update B and compute every M~ (or cut every sub-network)
  std::size_t ir_bytes = 0;  ///< total size of the IRs rebuilt
  int boundary_nodes = 0;    ///< |B| after the step
  int obstacle_nodes = 0;    ///< of which held by obstacles
  /// Sphere model: nodes the state has a sphere push that no IR's patch holds (its client
  /// cannot feel them); 0 unless the patches failed to settle in a step.
  int sphere_nodes_outside_patches = 0;
  /// Separation bodies: whether there is one, the area they have separated so far by
  /// fracture and by the laser [m^2], and whether a groove record is full (a groove it could
  /// not remember would be separated again by a later pass over it).
  bool separates = false;
  double fractured_m2 = 0, vaporised_m2 = 0;
  bool groove_record_full = false;

  /// Adds another body's report to this one.
  StepReport& operator+=(const StepReport& other) {
    rebuilt = rebuilt || other.rebuilt;
    recomputed = recomputed || other.recomputed;
    rebuild_ms += other.rebuild_ms;
    ir_bytes += other.ir_bytes;
    boundary_nodes += other.boundary_nodes;
    obstacle_nodes += other.obstacle_nodes;
    sphere_nodes_outside_patches += other.sphere_nodes_outside_patches;
    separates = separates || other.separates;
    fractured_m2 += other.fractured_m2;
    vaporised_m2 += other.vaporised_m2;
    groove_record_full = groove_record_full || other.groove_record_full;
    return *this;
  }
};

}  // namespace cohaptic
