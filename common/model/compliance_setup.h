// Preparing a model's compliance columns: from the on-disk cache when a valid one exists,
// otherwise by solving (the whole touchable block up front, or nothing until a node is
// asked for), and saving what was computed for next time.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "common/fem/compliance.h"
#include "common/model/elastic_body.h"
#include "common/util/progress_log.h"

namespace cohaptic {

/// The nodes whose compliance rows are kept: the touchable surface nodes, or the whole
/// surface (`whole_surface`) when nodes outside the touchable region can be held: the
/// scene has obstacles, or step-delay boundary nodes are asked for. Ordered in spatially
/// compact solve groups (compact_groups.h).
std::vector<int> compliance_row_nodes(const ElasticBody& body, bool whole_surface);

struct ComplianceSetup {
  bool from_disk = false;
  std::size_t columns = 0;           ///< columns available after setup
  double ms = 0;                     ///< time spent (load or solve, and save)
  std::filesystem::path cache_file;  ///< empty when the disk cache is off
  std::string note;                  ///< what happened with the cache, for the log
};

/// $XDG_CACHE_HOME/cohaptic, else $HOME/.cache/cohaptic, else ./.cohaptic-cache.
std::filesystem::path default_cache_directory();

/// Fills `columns` for `model` per its scene's compliance settings (precompute: the
/// touchable nodes' columns). `cache_directory`
/// empty disables the disk cache. A cache that cannot be written is logged, not fatal.
ComplianceSetup prepare_compliance(const ElasticBody& body, ComplianceColumns& columns,
                                   const std::optional<std::filesystem::path>& cache_directory);

/// Saves the columns computed so far (e.g. on-demand columns at shutdown), reporting to
/// `progress` if given. Logs failures.
void save_compliance(const ElasticBody& body, const ComplianceColumns& columns,
                     const std::filesystem::path& cache_directory, ProgressLog* progress = nullptr);

}  // namespace cohaptic
