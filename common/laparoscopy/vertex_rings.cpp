#include "common/laparoscopy/vertex_rings.h"

#include <algorithm>
#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {

VertexRings vertex_rings(std::span<const Triangle> triangles, int vertex_count) {
  std::vector<std::vector<int>> rings(static_cast<std::size_t>(std::max(vertex_count, 0)));
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int v = triangles[t][static_cast<std::size_t>(k)];
      if (v < 0 || v >= vertex_count)
        throw Error(
            fmt::format("vertex rings: triangle {} names vertex {}, but there are {} vertices", t,
                        v, vertex_count));
    }
    for (int k = 0; k < 3; ++k) {
      const int a = triangles[t][static_cast<std::size_t>(k)],
                b = triangles[t][static_cast<std::size_t>((k + 1) % 3)];
      rings[static_cast<std::size_t>(a)].push_back(b);
      rings[static_cast<std::size_t>(b)].push_back(a);
    }
  }
  VertexRings out;
  out.offsets.reserve(rings.size() + 1);
  out.offsets.push_back(0);
  for (auto& ring : rings) {
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
    out.vertices.insert(out.vertices.end(), ring.begin(), ring.end());
    out.offsets.push_back(static_cast<int>(out.vertices.size()));
  }
  return out;
}

}  // namespace cohaptic
