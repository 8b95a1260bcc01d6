#include "common/mesh/tet_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>

namespace cohaptic {

double signed_volume(const TetMesh& mesh, int t) {
  const Tet& e = mesh.tets[t];
  const Eigen::Vector3d x0 = mesh.nodes.col(e[0]);
  const Eigen::Vector3d a = mesh.nodes.col(e[1]) - x0;
  const Eigen::Vector3d b = mesh.nodes.col(e[2]) - x0;
  const Eigen::Vector3d c = mesh.nodes.col(e[3]) - x0;
  return a.cross(b).dot(c) / 6.0;
}

int node_index_from_tag(const TetMesh& mesh, std::int64_t tag) {
  const auto it = std::find(mesh.node_tags.begin(), mesh.node_tags.end(), tag);
  return it == mesh.node_tags.end() ? -1 : static_cast<int>(it - mesh.node_tags.begin());
}

std::unordered_map<std::int64_t, int> node_indices_by_tag(const TetMesh& mesh) {
  std::unordered_map<std::int64_t, int> index_of_tag;
  for (std::size_t n = 0; n < mesh.node_tags.size(); ++n)
    index_of_tag.emplace(mesh.node_tags[n], static_cast<int>(n));
  return index_of_tag;
}

}  // namespace cohaptic
