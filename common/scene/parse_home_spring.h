// The keys of a `model: home_spring` scene object and of an instrument tool (`shape: probe`
// or `shape: forceps`) (docs/laparoscopy.md, "Laparoscopic instruments"), validated with the scene
// loader's errors (file:line: key.path: expected ..., found ...).
#pragma once

#include <filesystem>

#include "common/laparoscopy/home_spring_spec.h"
#include "common/scene/scene_files.h"
#include "common/util/yaml_cursor.h"

namespace cohaptic {

/// `c` is the object's map (with name and model); lengths are scaled by `scale` [m/unit];
/// a surface file is resolved and checked by `files`.
HomeSpringObjectSpec parse_home_spring_object(const YamlCursor& c, double scale,
                                              const SceneFiles& files);

/// The instrument keys of a tool map `c` (trocar; for forceps, jaws); `forceps` says which.
InstrumentSpec parse_instrument(const YamlCursor& c, double scale, bool forceps);

}  // namespace cohaptic
