// The keys of a `model: separation` scene object (docs/separation.md, "Separating tissue"),
// validated with the scene loader's errors (file:line: key.path: expected ..., found ...).
#pragma once

#include "common/scene/scene_files.h"
#include "common/separation/separation_object_spec.h"
#include "common/util/yaml_cursor.h"

namespace cohaptic {

/// `c` is the object's map (with name and model); lengths are scaled by `scale` [m/unit];
/// mesh files resolve through `files`.
SeparationObjectSpec parse_separation_object(const YamlCursor& c, double scale,
                                             const SceneFiles& files);

}  // namespace cohaptic
