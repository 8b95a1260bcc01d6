// ElasticBody: a linear elastic FEM solid compiled from its scene object (`model:
// linear_elastic`), never changed afterwards: the mesh in metres, its boundary surface and
// pseudo-normals, the dof map, the stiffness K and the CHOLMOD factor of K_ff (computed
// when first asked for: see DeferredCholesky), and the touchable region. One of the body kinds a
// Model holds (model.h).
//
// Functions that only need the body take it as const&; what the loops mutate (tool
// positions, active sets, compliance columns computed on demand) lives elsewhere.
// Units: SI. Node indices are 0-based volume-mesh indices; mesh.node_tags gives the ids
// a user sees.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "common/contact/aabb_tree.h"
#include "common/contact/sphere_contact.h"
#include "common/contact/surface_distance.h"
#include "common/fem/assemble_stiffness.h"
#include "common/fem/dof_map.h"
#include "common/fem/deferred_cholesky.h"
#include "common/mesh/boundary_surface.h"
#include "common/mesh/mesh_checks.h"
#include "common/scene/scene.h"

namespace cohaptic {

struct ElasticBodyTimings {
  double mesh_ms = 0;      ///< read or generate, check, extract the surface
  double assemble_ms = 0;  ///< K
};

struct ElasticBody {
  std::string name;  ///< the scene object's name
  ElasticObjectSpec spec;
  TetMesh mesh;
  BoundarySurface surface;
  SurfacePseudoNormals normals;
  AabbTree surface_tree;  ///< over surface.triangles (same indices), for queries near a point
  MeshCheckReport mesh_report;
  DofMap dofs;
  SparseMatrix stiffness;                ///< K, 3N x 3N [N/m]
  DeferredCholesky free_factor;          ///< K_ff's factor (factor_ms(): its time)
  std::vector<int> touchable_nodes;      ///< sorted volume node indices
  std::vector<int> touchable_triangles;  ///< surface triangle indices
  /// Per volume node: the inward unit normal of its touchable triangles, the direction a
  /// sphere tool pushes it (contact_normals, sphere_contact.h); zero off them.
  Eigen::Matrix3Xd contact_normals;
  ElasticBodyTimings timings;

  /// "node <tag> axis <x|y|z>" for global dof `dof`, for messages.
  std::string describe_dof(int dof) const;
};

/// Compiles the FEM object `object` whose spec is `spec` (its alternative of object.body);
/// mesh files are scaled by `metres_per_unit`. Throws SceneError (a selector that selects
/// nothing, an unknown node id) or MeshError with a message naming the cause and
/// object.where. Logs mesh warnings through spdlog. K_ff is factored when first asked for
/// (NumericalError then if it is not positive definite).
ElasticBody build_elastic_body(const ObjectSpec& object, const ElasticObjectSpec& spec,
                               double metres_per_unit);

/// Nodes chosen by `selector`; `surface_only` restricts to boundary nodes. Sorted.
/// Throws SceneError naming selector.where if it selects nothing or names an unknown id.
std::vector<int> select_nodes(const NodeSelector& selector, const TetMesh& mesh,
                              const BoundarySurface& surface, bool surface_only);

/// Tags of the nodes with at least one fixed axis, ascending.
std::vector<std::int64_t> fixed_node_tags(const ElasticBody& body);

}  // namespace cohaptic
