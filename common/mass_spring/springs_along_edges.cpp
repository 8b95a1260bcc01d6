#include "common/mass_spring/springs_along_edges.h"

#include <algorithm>
#include <utility>

#include "common/util/error.h"

namespace cohaptic {

std::vector<Spring> springs_along_edges(const TetMesh& mesh, double stiffness, double damping) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(6 * mesh.tets.size());
  for (const Tet& tet : mesh.tets)
    for (std::size_t i = 0; i < 4; ++i)
      for (std::size_t j = i + 1; j < 4; ++j) edges.emplace_back(std::minmax(tet[i], tet[j]));
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<Spring> springs;
  springs.reserve(edges.size());
  for (const auto& [a, b] : edges) {
    const double length = (mesh.nodes.col(b) - mesh.nodes.col(a)).norm();
    if (!(length > 0))
      throw Error(fmt::format("springs along edges: nodes {} and {} are at one point", a, b));
    springs.push_back({a, b, length, stiffness, damping});
  }
  return springs;
}

}  // namespace cohaptic
