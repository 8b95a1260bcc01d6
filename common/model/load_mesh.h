// The tetrahedral mesh a scene's MeshSpec names: a generated box, a .msh file, or a Gmsh
// script meshed into the cache (common/mesh/mesh_with_gmsh.h). Units: m.
#pragma once

#include "common/mesh/tet_mesh.h"
#include "common/fem/mesh_spec.h"

namespace cohaptic {

/// The mesh in metres (a file's coordinates times `metres_per_unit`; a box is already in m).
/// Throws MeshError naming the file for one it cannot read.
TetMesh load_mesh(const MeshSpec& spec, double metres_per_unit);

}  // namespace cohaptic
