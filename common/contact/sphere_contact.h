// The sphere contact model's geometry: which surface nodes a rigid sphere tool may push,
// along which direction, and how far each is from it.
//
// The model is the linear elastic contact problem of Signorini, the one Hertz solved: the
// constraint is taken on the body's rest surface, along its own normal. Each touchable node
// has an inward unit normal n (its touchable triangles' angle-weighted normal, reversed): the
// direction a tool pushes it, frictionless, so that it may slide along the surface. Its gap
// g to a sphere is how far it must move along n to leave the sphere (g < 0: it lies inside)
// or may move before it reaches it (g > 0), measured along the line x + s n through its
// rest position: g = -s+, with s+ the far crossing of that line with the sphere. The node's
// displacement u must keep g + n . u >= 0, and the sphere pushes it with lambda n,
// lambda >= 0, released when holding it would pull (unilateral_contact_solve.h decides
// which). A node whose line misses the sphere, or meets it only ahead of the node (the
// sphere is inside the body beyond it), has no constraint from that sphere. Of several
// spheres the one with the least gap holds the node.
//
// As n does not depend on where the tools are, neither does the normal compliance between
// the nodes (W = N^T L N): a server computes it once per set of candidate nodes, and the
// gaps alone follow the tools.
//
// A rigid obstacle (the inner skull) constrains a surface node the same way, taken at rest
// and linear: with p the closest point to the node's rest position x on the nearest
// obstacle and m the obstacle's unit normal there (towards the allowed side), the node must
// keep g + m . u >= 0, g = m . (x - p) its signed distance; the obstacle pushes it with
// lambda m, lambda >= 0, frictionless, so that it slides along the obstacle's tangent plane
// at p and leaves it when holding it would pull. Of the spheres and the obstacle, the one
// with the least gap holds the node (ties to a sphere), along its own direction.
//
// A node the model cannot hold is no candidate: one without a touchable triangle (zero
// normal), or whose normal lies (to 1e-6) along its fixed axes (the support holds it
// there); for an obstacle, one whose obstacle normal does. Units: m.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "common/contact/aabb_tree.h"
#include "common/fem/dof_map.h"
#include "common/mesh/boundary_surface.h"
#include "common/mesh/tet_mesh.h"

namespace cohaptic {

/// A sphere tool; a non-finite centre means the tool is absent (it holds nothing).
struct SphereTool {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< [m]
  double radius = 0;                                 ///< [m]
};

/// One candidate node's constraint.
struct SphereConstraint {
  int tool = -1;   ///< index of the sphere with the least gap, or -1
  double gap = 0;  ///< [m]: negative inside, positive outside
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< the push's unit direction
  int obstacle = -1;  ///< the obstacle holding it (then tool = -1), or -1
};

/// The gap [m] of a node at `rest` with inward unit `normal` to `tool`: +inf when the line
/// along the normal misses the sphere or meets it only ahead of the node, or the tool is
/// absent (non-finite centre, no radius).
double sphere_gap(const Eigen::Vector3d& rest, const Eigen::Vector3d& normal,
                  const SphereTool& tool) noexcept;

/// Whether the model can hold a node with inward `normal` and `fixed` axes (see above).
bool holdable(const Eigen::Vector3d& normal, AxisMask fixed) noexcept;

/// The constraint on a node at `rest` with inward `normal` and `fixed` axes, from the
/// sphere of `tools` with the least gap (ties to the lower index); none if no sphere
/// constrains it or the model cannot hold it.
std::optional<SphereConstraint> sphere_constraint(const Eigen::Vector3d& rest,
                                                  const Eigen::Vector3d& normal, AxisMask fixed,
                                                  std::span<const SphereTool> tools) noexcept;

/// The constraint on a node from `tools` (sphere_constraint) or from its `obstacle`
/// constraint (null: none), whichever has the least gap, ties to a sphere.
std::optional<SphereConstraint> node_constraint(const Eigen::Vector3d& rest,
                                                const Eigen::Vector3d& normal, AxisMask fixed,
                                                std::span<const SphereTool> tools,
                                                const SphereConstraint* obstacle) noexcept;

/// The inward unit normal of every node of `triangles` (a body's touchable triangles): the
/// angle-weighted mean of their outward normals, reversed; zero for every other node (one
/// column per volume node).
Eigen::Matrix3Xd contact_normals(const TetMesh& mesh, const BoundarySurface& surface,
                                 std::span<const int> triangles);

/// The distinct nodes of surface `triangles`, ascending (the candidates of the touchable
/// triangles, say).
std::vector<int> triangle_nodes(const BoundarySurface& surface, std::span<const int> triangles);

/// Nodes (volume node indices) with their constraints.
struct SphereCandidates {
  std::vector<int> nodes;
  std::vector<SphereConstraint> constraints;
};

/// Of `nodes`, every candidate of `tools`, in order; `normals` per volume node (contact_normals).
SphereCandidates sphere_candidates(const TetMesh& mesh, const DofMap& dofs,
                                   const Eigen::Matrix3Xd& normals, std::span<const int> nodes,
                                   std::span<const SphereTool> tools);

/// Of `nodes`, those that `tools` hold at rest (the candidates inside a sphere), in order.
SphereCandidates nodes_held_by_spheres(const TetMesh& mesh, const DofMap& dofs,
                                       const Eigen::Matrix3Xd& normals, std::span<const int> nodes,
                                       std::span<const SphereTool> tools);

/// The patch of a sphere tool: `nearest` (the allowed triangle nearest the centre) first,
/// then every allowed triangle with a node inside the sphere or among `carried`, then
/// `rings` rings of allowed neighbours around them (contact_patch.h). Its nodes are the
/// tool's candidate nodes in an intermediate representation: every node the sphere holds
/// at rest, and those it may reach, or the deformation may carry into it, before the next
/// one. `carried`: nodes outside the sphere at rest that the solved state has it push
/// (the simulation finds them: a bulge can carry a node in beyond the rings).
/// `surface_tree`: an AabbTree over the surface's triangles (indices as in `surface`),
/// through which only the triangles near the sphere are looked at.
std::vector<int> sphere_patch(const TetMesh& mesh, const BoundarySurface& surface,
                              const AabbTree& surface_tree, int nearest, const SphereTool& tool,
                              int rings, const std::vector<bool>& allowed,
                              std::span<const int> carried = {});

}  // namespace cohaptic
