// TetMesh: a volume mesh of 4-node tetrahedra, the geometry every FEM model is built on.
//
// Units: metres (convert scene units on load). Invariants once a mesh is prepared
// (see prepare_tet_mesh): every node is used by at least one tetrahedron, and every
// tetrahedron has positive volume with the node order (0,1,2,3) right-handed, i.e.
// (x1-x0) x (x2-x0) . (x3-x0) > 0. node_tags/tet_tags keep the ids of the source file
// so that everything reported to a user can name nodes and elements as the file does.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace cohaptic {

using Tet = std::array<int, 4>;
using Triangle = std::array<int, 3>;

/// Whether two triangles (node indices) have a node in common. Where two tools press such
/// triangles, a node would have to follow both: the later tool is left out (the client's
/// evaluation, the server's state).
constexpr bool share_a_node(const Triangle& a, const Triangle& b) noexcept {
  for (int x : a)
    for (int y : b)
      if (x == y) return true;
  return false;
}

struct TetMesh {
  Eigen::Matrix3Xd nodes;               ///< rest positions [m], one column per node
  std::vector<Tet> tets;                ///< 0-based node indices
  std::vector<std::int64_t> node_tags;  ///< id of each node in its source (1-based if generated)
  std::vector<std::int64_t> tet_tags;   ///< id of each tetrahedron in its source

  int node_count() const { return static_cast<int>(nodes.cols()); }
  int tet_count() const { return static_cast<int>(tets.size()); }
};

/// Signed volume of tetrahedron t: positive when its node order is right-handed.
double signed_volume(const TetMesh& mesh, int t);

/// Index of the node whose tag is `tag`, or -1. Linear scan: for user input, not inner loops.
int node_index_from_tag(const TetMesh& mesh, std::int64_t tag);

/// The index of every node by its tag, for many look-ups.
std::unordered_map<std::int64_t, int> node_indices_by_tag(const TetMesh& mesh);

}  // namespace cohaptic
