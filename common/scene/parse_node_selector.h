// The scene file's node selectors (docs/scene-files.md, "Scene files": surface, box, plane or
// nodes), validated with the scene loader's errors (file:line: key.path: expected ..., found ...).
#pragma once

#include "common/mesh/node_selector.h"
#include "common/util/yaml_cursor.h"

namespace cohaptic {

/// `c` is the selector's map; lengths are scaled by `scale` [m/unit]. The caller checks the
/// keys allowed beside the selector (e.g. `axes` for a fixed region).
NodeSelector parse_node_selector(const YamlCursor& c, double scale);

}  // namespace cohaptic
