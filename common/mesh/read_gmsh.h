// Reader for Gmsh .msh meshes, ASCII format versions 2.2 and 4.1 (detected from $MeshFormat).
//
// Only 4-node tetrahedra (Gmsh element type 4) become the volume mesh; other elements
// (surface triangles, lines, points, ...) are counted per type, noted once per type in the
// log, and skipped. Nodes that no tetrahedron uses are dropped; otherwise the file's order
// is kept. Coordinates are returned exactly as written (file units: the scene converts),
// node and element tags as in the file. Tetrahedra keep the file's node order (orientation
// is checked later, by prepare_tet_mesh). Sections other than $MeshFormat, $Nodes and
// $Elements ($PhysicalNames, $Entities, $NodeData, ...) are skipped.
// Every problem in the file throws ParseError whose message starts "file:line:".
#pragma once

#include <filesystem>
#include <istream>
#include <map>
#include <string>

#include "common/mesh/tet_mesh.h"

namespace cohaptic {

struct GmshMesh {
  TetMesh mesh;                          ///< file coordinates; tets = the Gmsh type-4 elements
  std::map<int, long> skipped_elements;  ///< Gmsh element type -> count of elements skipped
  long unused_nodes_dropped = 0;         ///< nodes not referenced by any tetrahedron
};

/// Reads `path`. Throws Error if it cannot be opened, ParseError if it is malformed.
GmshMesh read_gmsh(const std::filesystem::path& path);

/// Parses .msh text; `source_name` starts every error message ("source_name:line: ...").
GmshMesh parse_gmsh(std::istream& in, const std::string& source_name);

/// Readable name of a Gmsh element type, e.g. "3-node triangle"; "unknown type" otherwise.
std::string gmsh_element_type_name(int type);

}  // namespace cohaptic
