// The sphere contact model's geometry: which surface nodes a rigid sphere tool may hold,
// and along which normal.
//
// Every touchable surface node is a candidate of the sphere nearest it (the smallest gap;
// ties to the lower tool index): held on that sphere's surface along the sphere's normal,
// frictionless (the node may slide along the surface), and released when holding it would
// pull (unilateral_contact_solve.h decides which). As the FEM is linear, so is the
// constraint: the normal n = (x - c) / |x - c| and the gap g = |x - c| - r are taken at
// rest, and the node's displacement u must satisfy g + n . u >= 0 (it ends on or outside
// the sphere along n); the tool pushes it with lambda n, lambda >= 0. A node inside a
// sphere at rest has g < 0 and the sphere "holds" it; one outside (g > 0) is pushed only
// when the deformation carries it in, so the force is continuous in the tool's position.
// Most candidates are far and never pushed: working_set_contact_solve.h solves over the
// few that are.
//
// A node the model cannot hold is no candidate: one within 1e-9 r of a centre (it has no
// normal), or one whose normal lies (to 1e-6) along its fixed axes (the support holds it
// there). Units: m.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

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
  int tool = -1;                                     ///< index of the sphere nearest it
  double gap = 0;                                    ///< |x - c| - r [m]: negative inside, positive outside
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit, from c through x: the push's direction
};

/// The constraint on a node at rest position `rest`, with `fixed` axes, from the nearest of
/// `tools`; none if there is no sphere or the model cannot hold the node (see above).
std::optional<SphereConstraint> sphere_constraint(const Eigen::Vector3d& rest, AxisMask fixed,
                                                  std::span<const SphereTool> tools) noexcept;

/// The distinct nodes of surface `triangles`, ascending (the candidates of the touchable
/// triangles, say).
std::vector<int> triangle_nodes(const BoundarySurface& surface, std::span<const int> triangles);

/// Nodes (volume node indices) with their constraints.
struct SphereCandidates {
  std::vector<int> nodes;
  std::vector<SphereConstraint> constraints;
};

/// Of `nodes`, every candidate of `tools`, in order.
SphereCandidates sphere_candidates(const TetMesh& mesh, const DofMap& dofs, std::span<const int> nodes,
                                   std::span<const SphereTool> tools);

/// Of `nodes`, those that `tools` hold at rest (the candidates inside a sphere), in order.
SphereCandidates nodes_held_by_spheres(const TetMesh& mesh, const DofMap& dofs, std::span<const int> nodes,
                                       std::span<const SphereTool> tools);

/// The patch of a sphere tool: `nearest` (the allowed triangle nearest the centre) first,
/// then every allowed triangle with a node inside the sphere or among `carried`, then
/// `rings` rings of allowed neighbours around them (contact_patch.h). Its nodes are the
/// tool's candidate nodes in an intermediate representation: every node the sphere holds
/// at rest, and those it may reach, or the deformation may carry into it, before the next
/// one. `carried`: nodes outside the sphere at rest that the solved state has it push
/// (the simulation finds them: a bulge can carry a node in beyond the rings).
std::vector<int> sphere_patch(const TetMesh& mesh, const BoundarySurface& surface, int nearest, const SphereTool& tool,
                              int rings, const std::vector<bool>& allowed, std::span<const int> carried = {});

}  // namespace cohaptic
