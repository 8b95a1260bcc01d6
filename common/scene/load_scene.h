// Loading and validating a YAML scene file (format in docs/scene-files.md, "Scene files").
//
// Every problem is reported as a SceneError whose message names the file, the line,
// the key path (e.g. objects[0].material.poisson_ratio), what was expected and what was
// found. Unknown keys are errors too, so a typo never silently falls back to a default.
#pragma once

#include <filesystem>
#include <string>

#include "common/scene/scene.h"
#include "common/scene/scene_files.h"
#include "common/util/error.h"

namespace cohaptic {

class SceneError : public Error {
 public:
  using Error::Error;
};

Scene load_scene(const std::filesystem::path& file);

/// Parses scene text; `file` names it in messages and resolves relative mesh paths; the
/// files it names are read as `access` allows (scene_files.h).
Scene parse_scene(const std::string& yaml_text, const std::filesystem::path& file,
                  const SceneFileAccess& access = {});

}  // namespace cohaptic
