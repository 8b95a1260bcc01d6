// Fuzz target: the Gmsh .msh reader (common/mesh/read_gmsh.h), followed by what a scene
// load does next with a mesh it read: the mesh checks and the boundary surface.
//
// Input: the text of a .msh file. Properties:
//   - parse_gmsh(), check_tet_mesh(), extract_boundary_surface() and
//     check_boundary_surface() either accept or throw
//     cohaptic::Error (ParseError, MeshError): nothing else escapes;
//   - a mesh read has one tag per node and per tetrahedron, finite coordinates, and every
//     tetrahedron's nodes in range;
//   - the surface of a checked mesh refers only to the mesh's nodes.
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>

#include "common/mesh/boundary_surface.h"
#include "common/mesh/mesh_checks.h"
#include "common/mesh/read_gmsh.h"
#include "common/util/error.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using namespace cohaptic;
using fuzz::require;

void require_well_formed(const TetMesh& mesh) {
  require(mesh.node_tags.size() == static_cast<std::size_t>(mesh.node_count()), "one tag per node");
  require(mesh.tet_tags.size() == mesh.tets.size(), "one tag per tetrahedron");
  require(mesh.nodes.allFinite(), "node coordinates are finite");
  for (const Tet& tet : mesh.tets)
    for (int node : tet)
      require(node >= 0 && node < mesh.node_count(), "tetrahedron nodes are in range");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    GmshMesh read = parse_gmsh(in, "fuzz.msh");
    require_well_formed(read.mesh);
    check_tet_mesh(read.mesh);
    require_well_formed(read.mesh);
    const BoundarySurface surface = extract_boundary_surface(read.mesh);
    for (const Triangle& triangle : surface.triangles)
      for (int node : triangle)
        require(node >= 0 && node < read.mesh.node_count(), "surface nodes are mesh nodes");
    check_boundary_surface(read.mesh, surface);
  } catch (const Error&) {
  }
  return 0;
}
