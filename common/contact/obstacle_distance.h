// ObstacleDistance: signed distance to a rigid obstacle (a plane or a triangle surface such
// as the inner skull) and the closest point on it, for colliding a deformable object with it.
//
// An obstacle splits space into the side the object lives on (allowed) and the forbidden
// side. Signed distance > 0 on the allowed side, < 0 when penetrating. Plane {point,
// normal}: the allowed side is where the normal points. Triangle surface: the sign comes
// from angle-weighted pseudo-normals (Baerentzen & Aanaes 2005), exact for a closed,
// consistently oriented manifold whatever the triangles' orientation (fixed by the sign of
// the enclosed volume); which side is allowed is decided once, at construction, from
// reference points (the object's rest surface nodes): at least 90 % of them must be on one
// side, else Error. An open surface (an edge without a consistently oriented neighbour)
// still works, using the face normal at such edges, with one warning at construction;
// its "inside" is then simply the side its triangles face away from, and the sign far
// beyond its rim means little. Queries use an AabbTree and allocate nothing.
// Units: those of the obstacle (m inside cohaptic).
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "common/contact/aabb_tree.h"
#include "common/contact/obstacle.h"

namespace cohaptic {

struct ObstaclePoint {
  Eigen::Vector3d point;       ///< closest point on the obstacle
  Eigen::Vector3d normal;      ///< unit, towards the allowed side: the gradient of the signed
                               ///< distance, i.e. +-(p - point)/|p - point|, or the surface's
                               ///< pseudo-normal when p is (nearly) on the surface
  double signed_distance = 0;  ///< > 0 allowed side, < 0 penetrating
  int triangle = -1;           ///< obstacle triangle of `point`; -1 for a plane
};

class ObstacleDistance {
 public:
  /// Prepares `obstacle`. `reference_points` (one column per point) decide the allowed side
  /// of a surface obstacle and are ignored for a plane. Throws Error naming the obstacle if
  /// it has neither plane nor triangles, a plane's normal is zero, there are no reference
  /// points for a surface, or fewer than 90 % of them are on one side.
  ObstacleDistance(const Obstacle& obstacle, const Eigen::Matrix3Xd& reference_points);

  double signed_distance(const Eigen::Vector3d& p) const;
  ObstaclePoint closest_point(const Eigen::Vector3d& p) const;

  const std::string& name() const { return name_; }
  bool is_plane() const { return is_plane_; }
  /// Every edge has one consistently oriented neighbour (always false for a plane).
  bool is_closed() const { return closed_; }
  /// The allowed side is the inside of the surface (false for a plane).
  bool allowed_inside() const { return allowed_inside_; }

 private:
  /// Closest point with the distance signed positive in front of the triangles' normals.
  ObstaclePoint closest_front_positive(const Eigen::Vector3d& p) const;
  Eigen::Vector3d feature_normal(int triangle, const Eigen::Vector3d& weights) const;

  std::string name_;
  bool is_plane_ = false;
  bool closed_ = false;
  bool allowed_inside_ = false;
  Eigen::Vector3d plane_point_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d plane_normal_ = Eigen::Vector3d::UnitZ();

  TriangleSurface surface_;
  AabbTree tree_;
  std::vector<std::array<int, 3>> neighbours_;  ///< triangle_edge_neighbours
  std::vector<Eigen::Vector3d> face_normals_;   ///< unit, along (b-a)x(c-a); zero if degenerate
  Eigen::Matrix3Xd vertex_normals_;             ///< unit angle-weighted pseudo-normals
  double allowed_sign_ = 1;  ///< multiplies the front-positive distance into allowed-positive
  double on_surface_ =
      0;  ///< below this distance, p counts as on the surface (normal = pseudo-normal)
};

}  // namespace cohaptic
