// Finding the contact of a tool with a deformable object at rest, and the paper's node
// translation of the contact triangle.
//
// A tool is a point, or a sphere of radius r. It is in contact when its point (centre)
// is less than r from the surface on the inside side, i.e. signed distance < r; the
// contact triangle is then the closest touchable surface triangle (ties at an edge or a
// vertex go to the triangle whose plane the tool is deepest below, then to the lower
// surface index). F is the closest
// point of that rest triangle (the foot of the perpendicular when it falls inside), w its
// area coordinates, and the node-translation displacement of each of the triangle's
// three nodes is d = (p - r n) - F with n the triangle's outward normal. Units: m.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>

#include "common/contact/surface_distance.h"

namespace cohaptic {

struct ToolContact {
  int triangle = -1;             ///< surface triangle index
  Eigen::Vector3d foot;          ///< F, on the rest triangle [m]
  Eigen::Vector3d weights;       ///< area coordinates of F
  Eigen::Vector3d displacement;  ///< d, the same for the three nodes [m]
  double depth = 0;              ///< -d . n: penetration below the contact triangle's plane [m]
};

struct ContactQuery {
  double signed_distance = 0;          ///< of the tool point to the whole surface [m]
  std::optional<ToolContact> contact;  ///< empty if the tool does not press a touchable triangle
};

/// The triangle of `triangles` nearest p (ties as above). Its signed_distance is the
/// height of p above that triangle's plane, not a surface distance.
SurfacePoint nearest_triangle(const TetMesh& mesh, const BoundarySurface& surface,
                              const SurfacePseudoNormals& normals, std::span<const int> triangles,
                              const Eigen::Vector3d& p);

/// `surface_candidates` limits the search for the surface distance (every triangle if empty;
/// see NearestTriangleCandidates), as `touchable_triangles` does for the contact triangle.
ContactQuery find_contact(const TetMesh& mesh, const BoundarySurface& surface,
                          const SurfacePseudoNormals& normals,
                          std::span<const int> touchable_triangles,
                          const Eigen::Vector3d& tool_position, double tool_radius,
                          std::span<const int> surface_candidates = {});

}  // namespace cohaptic
