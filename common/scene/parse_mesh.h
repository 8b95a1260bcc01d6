// The scene file's mesh of a tetrahedral body (file, gmsh or box) and its fixed regions
// (docs/scene-reference.md), validated with the scene loader's errors (file:line: key.path:
// expected ..., found ...).
#pragma once

#include <vector>

#include "common/fem/mesh_spec.h"
#include "common/scene/scene_files.h"
#include "common/util/yaml_cursor.h"

namespace cohaptic {

/// `c` is the `mesh` map; lengths are scaled by `scale` [m/unit]; files resolve through `files`.
MeshSpec parse_mesh(const YamlCursor& c, double scale, const SceneFiles& files);

/// `c` is the `fixed` list: at least one node selector, each with optional `axes`.
std::vector<FixedRegion> parse_fixed_regions(const YamlCursor& c, double scale);

}  // namespace cohaptic
