// The scene's `interactions:` list (docs/objects-that-press.md "Interactions in a scene"): pairs
// of objects that press on each other, each `{front: NAME, behind: NAME}`, validated with
// the scene loader's errors (file:line: key.path: expected ..., found ...) against the
// objects already parsed: both names exist, differ, the front is a mass-spring or a linear
// elastic object and the behind one linear elastic, and no front is paired twice.
#pragma once

#include <vector>

#include "common/scene/scene.h"
#include "common/util/yaml_cursor.h"

namespace cohaptic {

/// `list` is the `interactions` value; `objects` the scene's parsed objects.
std::vector<InteractionSpec> parse_interactions(const YamlCursor& list,
                                                const std::vector<ObjectSpec>& objects);

}  // namespace cohaptic
