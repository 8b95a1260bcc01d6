// How a scene describes a tetrahedral body's mesh and its supports, as loaded
// (common/scene/parse_mesh.h): a mesh file, a Gmsh script or a generated box, and the
// regions whose nodes are held. Plain data; load_mesh (common/model/load_mesh.h) builds the
// mesh and select_nodes (common/model/elastic_body.h) resolves the regions. Units: m.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>

#include "common/fem/dof_map.h"
#include "common/mesh/mesh_with_gmsh.h"
#include "common/mesh/node_selector.h"

namespace cohaptic {

struct BoxMeshSpec {
  Eigen::Vector3d min_corner = Eigen::Vector3d::Zero();  ///< [m]
  Eigen::Vector3d size = Eigen::Vector3d::Zero();        ///< [m]
  Eigen::Vector3i divisions = Eigen::Vector3i::Ones();
  Eigen::Vector3d grading =
      Eigen::Vector3d::Ones();  ///< per axis: each cell / the one before (box_mesher.h)
  Eigen::Vector3i uniform_cells =
      Eigen::Vector3i::Zero();  ///< per axis: equal cells on the fine side first
};

/// Exactly one of a mesh file (.msh 2.2/4.1, resolved against the scene's directory), a
/// Gmsh script that gmsh meshes when the scene is built (mesh_with_gmsh.h), or a box.
struct MeshSpec {
  std::filesystem::path file;
  std::optional<GmshScript> gmsh;
  std::optional<BoxMeshSpec> box;
};

struct FixedRegion {
  NodeSelector nodes;
  AxisMask axes = kAllAxes;  ///< fixing only some axes expresses a sliding boundary
};

}  // namespace cohaptic
