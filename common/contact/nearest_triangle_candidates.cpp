#include "common/contact/nearest_triangle_candidates.h"

#include <algorithm>
#include <cmath>

namespace cohaptic {

NearestTriangleCandidates::NearestTriangleCandidates(const TetMesh& mesh,
                                                     const BoundarySurface& surface,
                                                     std::span<const int> touchable_triangles)
    : all_(mesh.nodes, surface.triangles),
      every_triangle_touchable_(static_cast<int>(touchable_triangles.size()) ==
                                surface.triangle_count()) {
  if (every_triangle_touchable_) return;
  touchable_index_.assign(touchable_triangles.begin(), touchable_triangles.end());
  std::vector<Triangle> touchable;
  touchable.reserve(touchable_index_.size());
  for (int t : touchable_index_) touchable.push_back(surface.triangles[t]);
  touchable_ = AabbTree(mesh.nodes, touchable);
}

void NearestTriangleCandidates::near(const AabbTree& tree, std::span<const int> index,
                                     const Eigen::Vector3d& p, std::vector<int>& out) {
  out.clear();
  const AabbHit nearest = tree.closest_triangle(p);
  if (nearest.triangle < 0) return;
  tree.triangles_near(p, std::sqrt(nearest.distance2) * (1 + kSlack) + kReach, out);
  if (!index.empty())
    for (int& t : out) t = index[t];
  std::sort(out.begin(), out.end());
}

void NearestTriangleCandidates::find(const Eigen::Vector3d& p, std::vector<int>& surface,
                                     std::vector<int>& touchable) const {
  near(all_, {}, p, surface);
  if (every_triangle_touchable_)
    touchable = surface;
  else
    near(touchable_, touchable_index_, p, touchable);
}

}  // namespace cohaptic
