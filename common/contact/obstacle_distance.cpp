#include "common/contact/obstacle_distance.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "common/mesh/boundary_surface.h"
#include "common/util/error.h"
#include "common/util/not_a_number.h"

namespace cohaptic {
namespace {

/// Six times the volume enclosed by a closed surface: > 0 when its triangles face outwards.
double six_volume(const TriangleSurface& surface) {
  const Eigen::Vector3d origin =
      surface.vertices.rowwise().mean();  // keeps the sum well conditioned
  double sum = 0;
  for (const Triangle& tri : surface.triangles) {
    const Eigen::Vector3d a = surface.vertices.col(tri[0]) - origin;
    const Eigen::Vector3d b = surface.vertices.col(tri[1]) - origin;
    const Eigen::Vector3d c = surface.vertices.col(tri[2]) - origin;
    sum += a.dot(b.cross(c));
  }
  return sum;
}

}  // namespace

ObstacleDistance::ObstacleDistance(const Obstacle& obstacle,
                                   const Eigen::Matrix3Xd& reference_points)
    : name_(obstacle.name) {
  if (obstacle.plane) {
    const auto& [point, normal] = *obstacle.plane;
    if (!point.allFinite() || !normal.allFinite() || normal.norm() == 0)
      throw Error(fmt::format(
          "obstacle '{}': the plane's point or normal is not finite, or its normal is zero",
          name_));
    is_plane_ = true;
    plane_point_ = point;
    plane_normal_ = normal.normalized();
    return;
  }
  if (obstacle.surface.triangles.empty())
    throw Error(fmt::format("obstacle '{}' has neither a plane nor any triangles", name_));

  surface_ = obstacle.surface;
  tree_ = AabbTree(surface_);  // checks the indices and that the vertices are finite
  neighbours_ = triangle_edge_neighbours(surface_.triangles);
  int open_sides = 0;
  for (const auto& sides : neighbours_)
    open_sides += static_cast<int>(std::count(sides.begin(), sides.end(), -1));
  closed_ = open_sides == 0;

  face_normals_.reserve(surface_.triangles.size());
  vertex_normals_ = Eigen::Matrix3Xd::Zero(3, surface_.vertex_count());
  for (const Triangle& tri : surface_.triangles) {
    const Eigen::Vector3d x0 = surface_.vertices.col(tri[0]);
    const Eigen::Vector3d cross =
        (surface_.vertices.col(tri[1]) - x0).cross(surface_.vertices.col(tri[2]) - x0);
    const Eigen::Vector3d n =
        cross.norm() > 0 ? Eigen::Vector3d(cross.normalized()) : Eigen::Vector3d::Zero();
    face_normals_.push_back(n);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d x = surface_.vertices.col(tri[k]);
      const Eigen::Vector3d e1 = (surface_.vertices.col(tri[(k + 1) % 3]) - x).normalized();
      const Eigen::Vector3d e2 = (surface_.vertices.col(tri[(k + 2) % 3]) - x).normalized();
      const double angle = std::acos(std::clamp(e1.dot(e2), -1.0, 1.0));
      if (std::isfinite(angle)) vertex_normals_.col(tri[k]) += angle * n;
    }
  }
  for (int v = 0; v < surface_.vertex_count(); ++v)
    if (vertex_normals_.col(v).norm() > 0) vertex_normals_.col(v).normalize();

  const Eigen::Vector3d extent =
      surface_.vertices.rowwise().maxCoeff() - surface_.vertices.rowwise().minCoeff();
  on_surface_ = 1e-9 * extent.norm();
  if (!closed_)
    spdlog::warn(
        "obstacle '{}' is not a closed, consistently oriented surface: {} of its {} triangle sides "
        "have no "
        "consistently oriented neighbour; the signed distance uses face normals there, and its "
        "sign beyond the "
        "surface's rim may be wrong",
        name_, open_sides, 3 * surface_.triangle_count());

  // +1 if the triangles' normals point out of the enclosed volume, -1 if they point into it.
  const double front_is_outside = !closed_ || six_volume(surface_) >= 0 ? 1.0 : -1.0;
  const Eigen::Index count = reference_points.cols();
  if (count == 0)
    throw Error(fmt::format(
        "obstacle '{}': no reference points to decide which side of it the object is on", name_));
  Eigen::Index inside = 0, outside = 0;
  for (Eigen::Index i = 0; i < count; ++i) {
    const Eigen::Vector3d p = reference_points.col(i);
    if (!p.allFinite())
      throw Error(fmt::format("obstacle '{}': reference point {} is not finite", name_, i));
    const double s = front_is_outside * closest_front_positive(p).signed_distance;
    if (s < 0) ++inside;
    if (s > 0) ++outside;
  }
  if (10 * inside >= 9 * count) {
    allowed_inside_ = true;
    allowed_sign_ = -front_is_outside;
  } else if (10 * outside >= 9 * count) {
    allowed_inside_ = false;
    allowed_sign_ = front_is_outside;
  } else {
    const auto percent = [&](Eigen::Index n) {
      return 100.0 * static_cast<double>(n) / static_cast<double>(count);
    };
    const Eigen::Index on = count - inside - outside;
    throw Error(fmt::format(
        "the object is not on one side of obstacle '{}': {:.0f} % inside, {:.0f} % outside{}",
        name_, percent(inside), percent(outside),
        on > 0 ? fmt::format(", {:.0f} % on it", percent(on)) : std::string()));
  }
}

double ObstacleDistance::signed_distance(const Eigen::Vector3d& p) const {
  if (is_plane_) return (p - plane_point_).dot(plane_normal_);
  return allowed_sign_ * closest_front_positive(p).signed_distance;
}

ObstaclePoint ObstacleDistance::closest_point(const Eigen::Vector3d& p) const {
  if (is_plane_) {
    const double s = (p - plane_point_).dot(plane_normal_);
    return {p - s * plane_normal_, plane_normal_, s, -1};
  }
  ObstaclePoint result = closest_front_positive(p);
  result.signed_distance *= allowed_sign_;
  result.normal *= allowed_sign_;
  return result;
}

ObstaclePoint ObstacleDistance::closest_front_positive(const Eigen::Vector3d& p) const {
  const AabbHit hit = tree_.closest_triangle(p);
  ObstaclePoint result;
  result.triangle = hit.triangle;
  if (hit.triangle < 0) {  // only for a point that is not finite
    result.point = result.normal = Eigen::Vector3d::Constant(kNaN);
    result.signed_distance = kNaN;
    return result;
  }
  result.point = hit.closest.point;
  const Eigen::Vector3d n = feature_normal(hit.triangle, hit.closest.weights);
  const Eigen::Vector3d delta = p - result.point;
  const double distance = std::sqrt(hit.distance2);
  const bool behind = delta.dot(n) < 0;
  result.signed_distance = behind ? -distance : distance;
  result.normal =
      distance > on_surface_ ? Eigen::Vector3d((behind ? -delta : delta) / distance) : n;
  return result;
}

Eigen::Vector3d ObstacleDistance::feature_normal(int triangle,
                                                 const Eigen::Vector3d& weights) const {
  const Triangle& tri = surface_.triangles[triangle];
  int zeros = 0, nonzero_vertex = 0, zero_vertex = 0;
  for (int k = 0; k < 3; ++k) {
    if (weights[k] == 0) {
      ++zeros;
      zero_vertex = k;
    } else {
      nonzero_vertex = k;
    }
  }
  if (zeros == 2 && vertex_normals_.col(tri[nonzero_vertex]).squaredNorm() > 0)
    return vertex_normals_.col(tri[nonzero_vertex]);
  if (zeros == 1) {
    // The edge opposite the zero-weight vertex is side (zero_vertex + 1) = (v_k, v_k+1).
    const int neighbour = neighbours_[triangle][(zero_vertex + 1) % 3];
    if (neighbour >= 0) {
      const Eigen::Vector3d sum = face_normals_[triangle] + face_normals_[neighbour];
      if (sum.squaredNorm() > 0) return sum.normalized();
    }
  }
  if (face_normals_[triangle].squaredNorm() > 0) return face_normals_[triangle];
  // A degenerate triangle on an open side: blend its vertices' pseudo-normals.
  const Eigen::Vector3d blend = weights[0] * vertex_normals_.col(tri[0]) +
                                weights[1] * vertex_normals_.col(tri[1]) +
                                weights[2] * vertex_normals_.col(tri[2]);
  return blend.squaredNorm() > 0 ? Eigen::Vector3d(blend.normalized()) : Eigen::Vector3d::Zero();
}

}  // namespace cohaptic
