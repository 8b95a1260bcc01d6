#include "common/contact/find_contact.h"

#include <limits>

namespace cohaptic {

SurfacePoint nearest_triangle(const TetMesh& mesh, const BoundarySurface& surface, const SurfacePseudoNormals& normals,
                              std::span<const int> triangles, const Eigen::Vector3d& p) {
  // Closest triangle; among ties (an edge or vertex shared by several), the one whose
  // plane p is deepest below.
  SurfacePoint best;
  double best_distance2 = std::numeric_limits<double>::infinity();
  double best_height = std::numeric_limits<double>::infinity();
  for (int t : triangles) {
    const Triangle& tri = surface.triangles[t];
    const TriangleClosestPoint q =
        closest_point_on_triangle(p, mesh.nodes.col(tri[0]), mesh.nodes.col(tri[1]), mesh.nodes.col(tri[2]));
    const double d2 = (p - q.point).squaredNorm();
    const double height = (p - q.point).dot(normals.face[t]);
    const double tie_tolerance = 1e-24 + 1e-12 * best_distance2;
    const bool closer = d2 < best_distance2 - tie_tolerance;
    const bool same_distance = std::abs(d2 - best_distance2) <= tie_tolerance;
    const bool deeper = height < best_height - 1e-15 * std::abs(best_height);
    const bool same_height = !deeper && height <= best_height + 1e-15 * std::abs(best_height);
    if (best.triangle < 0 || closer || (same_distance && (deeper || (same_height && t < best.triangle)))) {
      best_distance2 = std::min(d2, best_distance2);
      best_height = height;
      best.triangle = t;
      best.closest = q;
    }
  }
  if (best.triangle >= 0) best.signed_distance = best_height;
  return best;
}

ContactQuery find_contact(const TetMesh& mesh, const BoundarySurface& surface, const SurfacePseudoNormals& normals,
                          std::span<const int> touchable_triangles, const Eigen::Vector3d& tool_position,
                          double tool_radius, std::span<const int> surface_candidates) {
  ContactQuery query;
  query.signed_distance = closest_surface_point(mesh, surface, normals, tool_position, surface_candidates).signed_distance;
  if (!(query.signed_distance < tool_radius) || touchable_triangles.empty()) return query;

  const SurfacePoint nearest = nearest_triangle(mesh, surface, normals, touchable_triangles, tool_position);
  ToolContact contact;
  contact.triangle = nearest.triangle;
  contact.foot = nearest.closest.point;
  contact.weights = nearest.closest.weights;
  const Eigen::Vector3d contact_point = tool_position - tool_radius * normals.face[contact.triangle];
  contact.displacement = contact_point - contact.foot;
  // Penetration below the contact triangle's plane, consistent with the displacement.
  contact.depth = -contact.displacement.dot(normals.face[contact.triangle]);
  query.contact = contact;
  return query;
}

}  // namespace cohaptic
