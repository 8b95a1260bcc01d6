// SeparationModel: a separating-tissue body compiled from its scene object
// (`model: separation`), never changed afterwards: the two bodies, their interface, the
// fields fitted to our FEM (from the scene cache when kept there) and the patch the haptic
// evaluation runs on, shared with every IR built from it. One of the body kinds a Model
// holds (common/model/model.h). Units: SI.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "common/scene/scene.h"
#include "common/separation/fracture_step.h"
#include "common/separation/separation_object_spec.h"
#include "common/separation/separation_setup.h"

namespace cohaptic {

struct SeparationModel {
  std::string name;  ///< the scene object's name
  SeparationObjectSpec spec;
  SeparationBodies bodies;
  SeparationInterface interface;
  std::shared_ptr<const SeparationPatch> patch;
  FieldPrecomputeReport report;  ///< zero when the fields came from the cache
  bool fields_from_cache = false;
  PlateauReach plateau;  ///< where the patch's l_n holds a pull at F_n (warned about if not all)
};

/// The program's cache for every separation object of `scene`: `directory`, or none at all.
void use_separation_field_cache(Scene& scene,
                                const std::optional<std::filesystem::path>& directory);

/// Builds the body (the fields from spec.cache_directory, or the default cache directory,
/// when spec.disk_cache); mesh files are scaled by `metres_per_unit`.
/// `force_limit` [N] is the scene's haptic limit, which the patch's own limit may not
/// exceed. Throws SceneError naming `where` for settings, meshes or supports the generator,
/// the interface or the fields refuse.
SeparationModel build_separation_body(const std::string& name, const SeparationObjectSpec& spec,
                                      double force_limit, double metres_per_unit,
                                      const std::string& where);

}  // namespace cohaptic
