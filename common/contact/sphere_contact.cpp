#include "common/contact/sphere_contact.h"

#include <algorithm>
#include <cmath>

#include "common/contact/contact_patch.h"

namespace cohaptic {
namespace {

constexpr double kCentreTolerance = 1e-9;      // of the radius: a node this near the centre has no normal
constexpr double kSmallestFreeNormal = 1e-6;   // below it the node's support holds it along the normal

}  // namespace

std::optional<SphereConstraint> sphere_constraint(const Eigen::Vector3d& rest, AxisMask fixed,
                                                  std::span<const SphereTool> tools) noexcept {
  std::optional<SphereConstraint> nearest;
  for (int t = 0; t < static_cast<int>(tools.size()); ++t) {
    const SphereTool& tool = tools[static_cast<std::size_t>(t)];
    if (!tool.centre.allFinite() || !(tool.radius > 0)) continue;
    const Eigen::Vector3d offset = rest - tool.centre;
    const double distance = offset.norm();
    const double gap = distance - tool.radius;
    if (distance <= kCentreTolerance * tool.radius) continue;
    if (nearest && !(gap < nearest->gap)) continue;
    const Eigen::Vector3d normal = offset / distance;
    Eigen::Vector3d free_part = normal;
    for (int axis = 0; axis < 3; ++axis)
      if ((fixed >> axis) & 1u) free_part[axis] = 0;
    if (free_part.norm() < kSmallestFreeNormal) continue;
    nearest = SphereConstraint{t, gap, normal};
  }
  return nearest;
}

std::vector<int> triangle_nodes(const BoundarySurface& surface, std::span<const int> triangles) {
  std::vector<int> nodes;
  for (int t : triangles)
    for (int node : surface.triangles[t]) nodes.push_back(node);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

SphereCandidates sphere_candidates(const TetMesh& mesh, const DofMap& dofs, std::span<const int> nodes,
                                   std::span<const SphereTool> tools) {
  SphereCandidates candidates;
  for (int node : nodes)
    if (const auto constraint = sphere_constraint(mesh.nodes.col(node), dofs.fixed_axes[node], tools)) {
      candidates.nodes.push_back(node);
      candidates.constraints.push_back(*constraint);
    }
  return candidates;
}

SphereCandidates nodes_held_by_spheres(const TetMesh& mesh, const DofMap& dofs, std::span<const int> nodes,
                                       std::span<const SphereTool> tools) {
  SphereCandidates held;
  for (int node : nodes)
    if (const auto constraint = sphere_constraint(mesh.nodes.col(node), dofs.fixed_axes[node], tools);
        constraint && constraint->gap < 0) {
      held.nodes.push_back(node);
      held.constraints.push_back(*constraint);
    }
  return held;
}

std::vector<int> sphere_patch(const TetMesh& mesh, const BoundarySurface& surface, int nearest, const SphereTool& tool,
                              int rings, const std::vector<bool>& allowed, std::span<const int> carried) {
  std::vector<int> seeds{nearest};
  const auto is_carried = [&](int node) { return std::find(carried.begin(), carried.end(), node) != carried.end(); };
  for (int t = 0; t < surface.triangle_count(); ++t) {
    if (!allowed[t] || t == nearest) continue;
    for (int node : surface.triangles[t])
      // held at rest, as nodes_held_by_spheres decides, or carried in
      if ((mesh.nodes.col(node) - tool.centre).norm() - tool.radius < 0 || is_carried(node)) {
        seeds.push_back(t);
        break;
      }
  }
  return contact_patch(surface, seeds, rings, allowed);
}

}  // namespace cohaptic
