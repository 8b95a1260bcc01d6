// `cohaptic-lab probe`: the static reaction force at given tool positions, from the
// command line, through the same intermediate representation and force evaluator the
// haptic loop uses (or the full sparse solve with --reference), with the contact it came
// from, the IR's size and how long each stage took.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "common/ir/intermediate_representation.h"
#include "common/scene/scene.h"
#include "lab/lab_command.h"

namespace cohaptic {

struct ProbeOptions {
  std::filesystem::path scene;
  std::vector<Eigen::Vector3d> tools;  ///< in the scene's units
  bool separately = false;             ///< press each tool alone instead of all at once
  bool json = false;
  bool reference = false;  ///< full sparse solve instead of the IR
  int boundary_nodes = 0;  ///< step-delay boundary nodes held at rest
  /// Simulation steps that bring each tool from touching to its position (1: one step from
  /// rest). Obstacles hold the nodes where they reach them, so their set depends on the path;
  /// with more than one, the last position is stepped again until no set changes.
  int approach_steps = 1;
  std::optional<int> patch_rings;             ///< default: the scene's
  std::optional<ContactModel> contact_model;  ///< default: the scene's
  IrPrecision precision = IrPrecision::f64;
  std::filesystem::path export_vtu;  ///< empty: no export
  std::filesystem::path export_msh;
  std::optional<std::filesystem::path> cache_directory;  ///< empty: no disk cache
};

/// Runs the probe, printing a table (or JSON) on stdout. Returns the process exit code.
int run_probe(const ProbeOptions& options);

/// `cohaptic-lab probe --scene FILE --tool X,Y,Z [...]` (docs/lab-tools.md "`cohaptic-lab probe`").
LabCommand add_probe_command(CLI::App& lab);

}  // namespace cohaptic
