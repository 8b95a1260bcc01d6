#include "common/contact/contact_patch.h"

#include <algorithm>

namespace cohaptic {

std::vector<int> contact_patch(const BoundarySurface& surface, int triangle, int rings,
                               const std::vector<bool>& allowed) {
  return contact_patch(surface, std::span<const int>(&triangle, 1), rings, allowed);
}

std::vector<int> contact_patch(const BoundarySurface& surface, std::span<const int> seeds,
                               int rings, const std::vector<bool>& allowed) {
  std::vector<int> patch;
  std::vector<bool> in_patch(surface.triangles.size(), false);
  for (int t : seeds)
    if (!in_patch[t]) {
      in_patch[t] = true;
      patch.push_back(t);
    }
  std::size_t ring_begin = 0;
  for (int ring = 0; ring < rings; ++ring) {
    const std::size_t ring_end = patch.size();
    for (std::size_t i = ring_begin; i < ring_end; ++i)
      for (int node : surface.triangles[patch[i]])
        for (int t : surface.node_triangles(node))
          if (!in_patch[t] && allowed[t]) {
            in_patch[t] = true;
            patch.push_back(t);
          }
    ring_begin = ring_end;
  }
  return patch;
}

}  // namespace cohaptic
