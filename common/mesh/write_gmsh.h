// Writer for Gmsh .msh ASCII format 4.1, the format read_gmsh reads back bit-exactly.
//
// Layout: $MeshFormat, then $Nodes with one block (entity of dimension 3, tag 1) and
// $Elements with one block of 4-node tetrahedra (Gmsh type 4); no $Entities section, which
// MSH 4.1 allows (Gmsh then creates the entity itself). Coordinates are written with 17
// significant digits, so read_gmsh returns the same doubles. Node and element tags are
// mesh.node_tags / mesh.tet_tags (index + 1 where those are empty); they must be positive
// and unique. Nodes that no tetrahedron uses are written but read_gmsh drops them.
// The file is written to "<path>.tmp" and renamed: a failed write leaves no file.
#pragma once

#include <filesystem>

#include "common/mesh/tet_mesh.h"

namespace cohaptic {

/// Writes `mesh` to `path`. Throws Error if the mesh cannot be written as a valid .msh
/// (no tetrahedra, bad tags, node index out of range, non-finite coordinate) or if the
/// file cannot be written (the message names the path and the system's reason).
void write_gmsh41(const std::filesystem::path& path, const TetMesh& mesh);

}  // namespace cohaptic
