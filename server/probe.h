// `cohaptic-server probe`: the static reaction force at given tool positions, from the
// command line, with the contact it came from and how long each stage took.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace cohaptic {

struct ProbeOptions {
  std::filesystem::path scene;
  std::vector<Eigen::Vector3d> tools;  ///< in the scene's units
  bool separately = false;             ///< press each tool alone instead of all at once
  bool json = false;
  std::filesystem::path export_vtu;    ///< empty: no export
  std::filesystem::path export_msh;
  std::optional<std::filesystem::path> cache_directory;  ///< empty: no disk cache
};

/// Runs the probe, printing a table (or JSON) on stdout. Returns the process exit code.
int run_probe(const ProbeOptions& options);

}  // namespace cohaptic
