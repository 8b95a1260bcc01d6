// Model: everything compiled once from a Scene and never changed afterwards (after
// MuJoCo's mjModel): the mesh in metres, its boundary surface, the dof map, the stiffness
// K and the CHOLMOD factor of K_ff, the touchable region and the obstacles.
//
// Functions that only need the model take it as const&. What the loops mutate (tool
// positions, active sets, compliance columns computed on demand) lives elsewhere.
// Units: SI. Node indices are 0-based volume-mesh indices; mesh.node_tags gives the ids
// a user sees.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "common/contact/obstacle.h"
#include "common/contact/surface_distance.h"
#include "common/fem/assemble_stiffness.h"
#include "common/fem/dof_map.h"
#include "common/fem/sparse_cholesky.h"
#include "common/mesh/boundary_surface.h"
#include "common/mesh/mesh_checks.h"
#include "common/scene/scene.h"

namespace cohaptic {

struct ModelBuildTimings {
  double mesh_ms = 0;      ///< read or generate, check, extract the surface
  double assemble_ms = 0;  ///< K
  double factor_ms = 0;    ///< CHOLMOD analysis + factorisation of K_ff
};

struct Model {
  Scene scene;
  TetMesh mesh;
  BoundarySurface surface;
  SurfacePseudoNormals normals;
  MeshCheckReport mesh_report;
  DofMap dofs;
  SparseMatrix stiffness;                         ///< K, 3N x 3N [N/m]
  std::unique_ptr<SparseCholesky> free_factor;    ///< K_ff
  std::vector<int> touchable_nodes;               ///< sorted volume node indices
  std::vector<int> touchable_triangles;           ///< surface triangle indices
  std::vector<Obstacle> obstacles;
  ModelBuildTimings timings;

  /// "node <tag> axis <x|y|z>" for global dof `dof`, for messages.
  std::string describe_dof(int dof) const;
};

/// Compiles `scene`. Throws SceneError (a selector that selects nothing, an unknown node
/// id), MeshError or NumericalError (K_ff not positive definite) with a message naming
/// the cause. Logs mesh warnings through spdlog.
Model build_model(const Scene& scene);

/// Nodes chosen by `selector`; `surface_only` restricts to boundary nodes. Sorted.
/// Throws SceneError naming selector.where if it selects nothing or names an unknown id.
std::vector<int> select_nodes(const NodeSelector& selector, const TetMesh& mesh, const BoundarySurface& surface,
                              bool surface_only);

/// Tags of the nodes with at least one fixed axis, ascending.
std::vector<std::int64_t> fixed_node_tags(const Model& model);

}  // namespace cohaptic
