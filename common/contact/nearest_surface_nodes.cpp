#include "common/contact/nearest_surface_nodes.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include "common/util/error.h"

namespace cohaptic {

std::vector<int> nearest_surface_nodes(const TetMesh& mesh, const BoundarySurface& surface,
                                       const DofMap& dofs, std::span<const Eigen::Vector3d> points,
                                       int count, const std::vector<bool>& excluded) {
  std::vector<std::pair<double, int>> candidates;
  for (int node : surface.nodes) {
    if (dofs.fixed_axes[node] == kAllAxes || (!excluded.empty() && excluded[node])) continue;
    double nearest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& p : points)
      nearest = std::min(nearest, (mesh.nodes.col(node) - p).squaredNorm());
    candidates.emplace_back(nearest, node);
  }
  if (count > static_cast<int>(candidates.size()))
    throw Error(fmt::format(
        "{} boundary nodes asked for, but the surface has only {} nodes that can be held "
        "(movable and not in contact)",
        count, candidates.size()));
  std::partial_sort(candidates.begin(), candidates.begin() + count, candidates.end());
  std::vector<int> nodes;
  for (int i = 0; i < count; ++i) nodes.push_back(candidates[i].second);
  return nodes;
}

}  // namespace cohaptic
