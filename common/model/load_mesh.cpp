#include "common/model/load_mesh.h"

#include <spdlog/spdlog.h>

#include "common/mesh/box_mesher.h"
#include "common/mesh/read_gmsh.h"
#include "common/model/compliance_setup.h"

namespace cohaptic {

TetMesh load_mesh(const MeshSpec& spec, double metres_per_unit) {
  if (spec.box)
    return make_box_mesh(spec.box->min_corner, spec.box->size, spec.box->divisions,
                         spec.box->grading, spec.box->uniform_cells);
  const std::filesystem::path file =
      spec.gmsh ? mesh_with_gmsh(*spec.gmsh, default_cache_directory() / "meshes") : spec.file;
  GmshMesh gmsh = read_gmsh(file);
  if (gmsh.unused_nodes_dropped > 0)
    spdlog::info("{}: dropped {} nodes that no tetrahedron uses", file.string(),
                 gmsh.unused_nodes_dropped);
  gmsh.mesh.nodes *= metres_per_unit;
  return std::move(gmsh.mesh);
}

}  // namespace cohaptic
