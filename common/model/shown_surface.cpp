#include "common/model/shown_surface.h"

namespace cohaptic {

ShownSurface shown_surface(const ElasticBody& body, std::span<const int> row_nodes) {
  ShownSurface shown;
  shown.index_of.assign(static_cast<std::size_t>(body.mesh.node_count()), -1);
  for (int node : row_nodes) {
    shown.index_of[static_cast<std::size_t>(node)] = static_cast<int>(shown.nodes.size());
    shown.nodes.push_back(node);
  }
  const auto local = [&](int node) { return shown.index_of[static_cast<std::size_t>(node)]; };
  for (const Triangle& tri : body.surface.triangles)
    if (local(tri[0]) >= 0 && local(tri[1]) >= 0 && local(tri[2]) >= 0)
      shown.triangles.push_back({local(tri[0]), local(tri[1]), local(tri[2])});
  return shown;
}

}  // namespace cohaptic
