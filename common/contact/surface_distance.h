// Closest point on a tet mesh's boundary surface and the signed distance to it.
//
// The sign comes from angle-weighted pseudo-normals (Baerentzen & Aanaes 2005): negative
// inside the object, positive outside, correct at edges and vertices too, for a closed
// manifold surface. Units: m. The search is a linear scan over the candidate triangles.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/contact/closest_point_on_triangle.h"
#include "common/mesh/boundary_surface.h"

namespace cohaptic {

struct SurfacePseudoNormals {
  std::vector<Eigen::Vector3d> face;  ///< per surface triangle, unit outward
  Eigen::Matrix3Xd vertex;            ///< per volume node: unit angle-weighted normal (zero inside)
};

SurfacePseudoNormals compute_pseudo_normals(const TetMesh& mesh, const BoundarySurface& surface);

struct SurfacePoint {
  int triangle = -1;             ///< surface triangle index
  TriangleClosestPoint closest;  ///< point on that triangle and its area coordinates
  double signed_distance = 0;    ///< [m], negative inside
};

/// The feature of a triangle that a point with area coordinates `weights` lies on: its
/// face, edge (k, k+1) or vertex k, read from the exact zeros of the weights.
struct TriangleFeature {
  enum class Kind { face, edge, vertex };
  Kind kind = Kind::face;
  int index = 0;  ///< k for an edge (k, k+1) or a vertex k
};
TriangleFeature feature_of(const Eigen::Vector3d& weights);

/// Normalised sum of the normals of `triangle` and the triangle across its edge (k, k+1)
/// (the face normal alone where the edge has no single neighbour).
Eigen::Vector3d edge_pseudo_normal(const BoundarySurface& surface,
                                   const SurfacePseudoNormals& normals, int triangle, int k);

/// The pseudo-normal at the feature of `triangle` that `weights` lies on.
Eigen::Vector3d feature_normal(const BoundarySurface& surface, const SurfacePseudoNormals& normals,
                               int triangle, const Eigen::Vector3d& weights);

/// Closest point among `candidates` (every surface triangle if empty). The sign is
/// meaningful when the candidates cover the whole closed surface.
SurfacePoint closest_surface_point(const TetMesh& mesh, const BoundarySurface& surface,
                                   const SurfacePseudoNormals& normals, const Eigen::Vector3d& p,
                                   std::span<const int> candidates = {});

}  // namespace cohaptic
