// The compliance columns of every linear elastic body of a compiled scene, prepared
// (compliance_setup.h: from the disk cache or solved), for the scene's simulation: one set
// per FEM body, none for the other kinds.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "common/fem/compliance.h"
#include "common/model/model.h"

namespace cohaptic {

struct SceneCompliance {
  std::vector<std::unique_ptr<ComplianceColumns>> owned;
  std::vector<ComplianceColumns*>
      per_body;  ///< body i's columns; null when it is not linear elastic
  std::vector<std::size_t>
      columns_at_load;  ///< body i's column count once prepared (0 for the other kinds)
};

/// `whole_surface`: keep every surface node's rows (compliance_row_nodes), for obstacles or
/// step-delay nodes. `cache_directory` empty disables the disk cache.
SceneCompliance prepare_scene_compliance(
    const Model& model, bool whole_surface,
    const std::optional<std::filesystem::path>& cache_directory);

/// Saves the columns of each FEM body that computed some on demand since it was prepared
/// (save_compliance), for bodies whose scene settings keep a disk cache.
void save_scene_compliance(const Model& model, const SceneCompliance& compliance,
                           const std::filesystem::path& cache_directory);

}  // namespace cohaptic
