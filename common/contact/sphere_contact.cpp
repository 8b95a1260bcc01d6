#include "common/contact/sphere_contact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "common/contact/contact_patch.h"

namespace cohaptic {
namespace {

constexpr double kSmallestFreeNormal =
    1e-6;  // below it the node's support holds it along the normal

}  // namespace

double sphere_gap(const Eigen::Vector3d& rest, const Eigen::Vector3d& normal,
                  const SphereTool& tool) noexcept {
  constexpr double kNone = std::numeric_limits<double>::infinity();
  if (!tool.centre.allFinite() || !(tool.radius > 0)) return kNone;
  // The line x + s n meets the sphere where s^2 + 2 b s + c = 0.
  const Eigen::Vector3d offset = rest - tool.centre;
  const double b = normal.dot(offset), c = offset.squaredNorm() - tool.radius * tool.radius;
  const double discriminant = b * b - c;
  if (!(discriminant >= 0)) return kNone;
  const double root = std::sqrt(discriminant);
  if (-b - root > 0) return kNone;  // the sphere lies wholly ahead of the node
  // g = -s+ = b - root, written without cancellation where b > 0 (b^2 - root^2 = c).
  return b > 0 ? c / (b + root) : b - root;
}

bool holdable(const Eigen::Vector3d& normal, AxisMask fixed) noexcept {
  Eigen::Vector3d free_part = normal;
  for (int axis = 0; axis < 3; ++axis)
    if ((fixed >> axis) & 1u) free_part[axis] = 0;
  return free_part.norm() >= kSmallestFreeNormal;
}

std::optional<SphereConstraint> sphere_constraint(const Eigen::Vector3d& rest,
                                                  const Eigen::Vector3d& normal, AxisMask fixed,
                                                  std::span<const SphereTool> tools) noexcept {
  if (!holdable(normal, fixed)) return std::nullopt;
  std::optional<SphereConstraint> nearest;
  for (int t = 0; t < static_cast<int>(tools.size()); ++t) {
    const double gap = sphere_gap(rest, normal, tools[static_cast<std::size_t>(t)]);
    if (gap == std::numeric_limits<double>::infinity() || (nearest && !(gap < nearest->gap)))
      continue;
    nearest = SphereConstraint{t, gap, normal};
  }
  return nearest;
}

std::optional<SphereConstraint> node_constraint(const Eigen::Vector3d& rest,
                                                const Eigen::Vector3d& normal, AxisMask fixed,
                                                std::span<const SphereTool> tools,
                                                const SphereConstraint* obstacle) noexcept {
  std::optional<SphereConstraint> constraint = sphere_constraint(rest, normal, fixed, tools);
  if (obstacle && (!constraint || obstacle->gap < constraint->gap)) constraint = *obstacle;
  return constraint;
}

Eigen::Matrix3Xd contact_normals(const TetMesh& mesh, const BoundarySurface& surface,
                                 std::span<const int> triangles) {
  Eigen::Matrix3Xd normals = Eigen::Matrix3Xd::Zero(3, mesh.node_count());
  for (int t : triangles) {
    const Triangle& tri = surface.triangles[static_cast<std::size_t>(t)];
    const Eigen::Vector3d a = mesh.nodes.col(tri[0]), b = mesh.nodes.col(tri[1]),
                          c = mesh.nodes.col(tri[2]);
    const Eigen::Vector3d face = (b - a).cross(c - a).normalized();
    const std::array<Eigen::Vector3d, 3> corner = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d e1 =
          corner[static_cast<std::size_t>((k + 1) % 3)] - corner[static_cast<std::size_t>(k)];
      const Eigen::Vector3d e2 =
          corner[static_cast<std::size_t>((k + 2) % 3)] - corner[static_cast<std::size_t>(k)];
      const double angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
      normals.col(tri[k]) -= angle * face;  // inward
    }
  }
  for (Eigen::Index node = 0; node < normals.cols(); ++node)
    if (const double length = normals.col(node).norm(); length > 0) normals.col(node) /= length;
  return normals;
}

std::vector<int> triangle_nodes(const BoundarySurface& surface, std::span<const int> triangles) {
  std::vector<int> nodes;
  for (int t : triangles)
    for (int node : surface.triangles[t]) nodes.push_back(node);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

SphereCandidates sphere_candidates(const TetMesh& mesh, const DofMap& dofs,
                                   const Eigen::Matrix3Xd& normals, std::span<const int> nodes,
                                   std::span<const SphereTool> tools) {
  SphereCandidates candidates;
  for (int node : nodes)
    if (const auto constraint = sphere_constraint(mesh.nodes.col(node), normals.col(node),
                                                  dofs.fixed_axes[node], tools)) {
      candidates.nodes.push_back(node);
      candidates.constraints.push_back(*constraint);
    }
  return candidates;
}

SphereCandidates nodes_held_by_spheres(const TetMesh& mesh, const DofMap& dofs,
                                       const Eigen::Matrix3Xd& normals, std::span<const int> nodes,
                                       std::span<const SphereTool> tools) {
  SphereCandidates held;
  for (int node : nodes)
    if (const auto constraint = sphere_constraint(mesh.nodes.col(node), normals.col(node),
                                                  dofs.fixed_axes[node], tools);
        constraint && constraint->gap < 0) {
      held.nodes.push_back(node);
      held.constraints.push_back(*constraint);
    }
  return held;
}

std::vector<int> sphere_patch(const TetMesh& mesh, const BoundarySurface& surface,
                              const AabbTree& surface_tree, int nearest, const SphereTool& tool,
                              int rings, const std::vector<bool>& allowed,
                              std::span<const int> carried) {
  // Seeds beside `nearest`, ascending: the allowed triangles with a node held at rest, as
  // nodes_held_by_spheres decides (every one has its box within the radius of the centre),
  // or with a carried node.
  std::vector<int> near;
  surface_tree.triangles_near(tool.centre, tool.radius, near);
  std::erase_if(near, [&](int t) {
    if (!allowed[static_cast<std::size_t>(t)] || t == nearest) return true;
    for (int node : surface.triangles[static_cast<std::size_t>(t)])
      if ((mesh.nodes.col(node) - tool.centre).norm() - tool.radius < 0) return false;
    return true;
  });
  for (int node : carried)
    for (int t : surface.node_triangles(node))
      if (allowed[static_cast<std::size_t>(t)] && t != nearest) near.push_back(t);
  std::sort(near.begin(), near.end());
  near.erase(std::unique(near.begin(), near.end()), near.end());
  std::vector<int> seeds{nearest};
  seeds.insert(seeds.end(), near.begin(), near.end());
  return contact_patch(surface, seeds, rings, allowed);
}

}  // namespace cohaptic
