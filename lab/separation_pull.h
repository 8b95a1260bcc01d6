// `cohaptic-lab separation-pull`: the separation-forces paper's Fig. 10 reproduced on a
// scene's separating interface. A grasp holds the interface node nearest a point, pulls it
// away at a constant speed (along the normal, or tilted towards x by an angle) and brings
// it back (common/separation/pull_loop.h); the command writes the force against the
// deflection through the phases AB, BC and CA beside J_c l (fig10_force.svg), the separated
// shares against time (fig10_area.svg) and every sample (pull_loop.csv), and prints the
// threshold measured against J_c l, the separated area against l dz, the hand's work in BC
// against J_c times that area, and the loop's net work (>= 0: passive). Units on the
// command line: mm, mm/s, degrees.
#pragma once

#include <filesystem>
#include <vector>

#include "lab/lab_command.h"

namespace cohaptic {

struct SeparationPullOptions {
  std::filesystem::path scene = "scenes/separation/two_layers.yaml";
  std::vector<double> at_mm{
      0,
      20};  ///< the held node: the interface node nearest (x, y, 0) [mm], of any separation object
  double speed_mm_s = 10;
  double tilt_deg = 0;        ///< from the normal towards +x
  std::filesystem::path out;  ///< empty: the summary only
  bool disk_cache = true;     ///< the fields from (and into) the default cache directory
};

/// Runs the loop, prints the summary, writes the files. Returns the exit code.
int run_separation_pull(const SeparationPullOptions& options);

/// `cohaptic-lab separation-pull [--scene FILE] [--at X Y] [--speed MM/S] [--tilt DEG] [--out DIR]
/// [--no-disk-cache]`.
LabCommand add_separation_pull_command(CLI::App& lab);

}  // namespace cohaptic
