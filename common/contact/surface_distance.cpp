#include "common/contact/surface_distance.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace cohaptic {

SurfacePseudoNormals compute_pseudo_normals(const TetMesh& mesh, const BoundarySurface& surface) {
  SurfacePseudoNormals normals;
  normals.face.reserve(surface.triangles.size());
  normals.vertex = Eigen::Matrix3Xd::Zero(3, mesh.node_count());
  for (const Triangle& tri : surface.triangles) {
    const Eigen::Vector3d n = triangle_normal(mesh, tri);
    normals.face.push_back(n);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d x = mesh.nodes.col(tri[k]);
      const Eigen::Vector3d e1 = (mesh.nodes.col(tri[(k + 1) % 3]) - x).normalized();
      const Eigen::Vector3d e2 = (mesh.nodes.col(tri[(k + 2) % 3]) - x).normalized();
      const double angle = std::acos(std::clamp(e1.dot(e2), -1.0, 1.0));
      if (std::isfinite(angle) && n.allFinite()) normals.vertex.col(tri[k]) += angle * n;
    }
  }
  for (int node : surface.nodes) normals.vertex.col(node).normalize();
  return normals;
}

TriangleFeature feature_of(const Eigen::Vector3d& weights) {
  const int zeros = (weights[0] == 0) + (weights[1] == 0) + (weights[2] == 0);
  if (zeros == 1)
    return {TriangleFeature::Kind::edge, ((weights[0] == 0 ? 0 : weights[1] == 0 ? 1 : 2) + 1) % 3};
  if (zeros == 2)
    return {TriangleFeature::Kind::vertex, weights[0] != 0 ? 0 : weights[1] != 0 ? 1 : 2};
  return {};
}

Eigen::Vector3d edge_pseudo_normal(const BoundarySurface& surface,
                                   const SurfacePseudoNormals& normals, int triangle, int k) {
  const int neighbour = surface.triangle_neighbours[triangle][k];
  return neighbour >= 0
             ? Eigen::Vector3d((normals.face[triangle] + normals.face[neighbour]).normalized())
             : normals.face[triangle];
}

Eigen::Vector3d feature_normal(const BoundarySurface& surface, const SurfacePseudoNormals& normals,
                               int triangle, const Eigen::Vector3d& weights) {
  const TriangleFeature feature = feature_of(weights);
  switch (feature.kind) {
    case TriangleFeature::Kind::vertex:
      return normals.vertex.col(surface.triangles[triangle][feature.index]);
    case TriangleFeature::Kind::edge:
      return edge_pseudo_normal(surface, normals, triangle, feature.index);
    case TriangleFeature::Kind::face:
      break;
  }
  return normals.face[triangle];
}

SurfacePoint closest_surface_point(const TetMesh& mesh, const BoundarySurface& surface,
                                   const SurfacePseudoNormals& normals, const Eigen::Vector3d& p,
                                   std::span<const int> candidates) {
  SurfacePoint best;
  double best_distance2 = std::numeric_limits<double>::infinity();
  const auto consider = [&](int t) {
    const Triangle& tri = surface.triangles[t];
    const TriangleClosestPoint q = closest_point_on_triangle(
        p, mesh.nodes.col(tri[0]), mesh.nodes.col(tri[1]), mesh.nodes.col(tri[2]));
    const double d2 = (p - q.point).squaredNorm();
    if (d2 < best_distance2) {
      best_distance2 = d2;
      best.triangle = t;
      best.closest = q;
    }
  };
  if (candidates.empty()) {
    for (int t = 0; t < surface.triangle_count(); ++t) consider(t);
  } else {
    for (int t : candidates) consider(t);
  }
  if (best.triangle < 0) return best;
  const Eigen::Vector3d n = feature_normal(surface, normals, best.triangle, best.closest.weights);
  const double distance = std::sqrt(best_distance2);
  best.signed_distance = (p - best.closest.point).dot(n) < 0 ? -distance : distance;
  return best;
}

}  // namespace cohaptic
