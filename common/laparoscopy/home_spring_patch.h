// HomeSpringPatch: the laparoscopy paper's spring force model (its Eq. 8) around one
// instrument's contact, as plain data: what the intermediate representation carries for a
// home-spring body, evaluated by the client at its haptic rate and by the server for P0.
//
// Every surface vertex is tied to its rest position by a home spring (k1) and to each
// neighbour of its 1-ring by a spring of rest length d_j (k2); with a damping c, a dashpot
// beside the home spring makes the vertex viscoelastic (viscous_home_spring.h). Only the
// vertex the tool holds, or the one it let go of, moves; its neighbours stay at rest (the paper's
// model: force and display deformation are decoupled). The patch is a piece of the body's surface
// near the tool: its first `contact_vertex_count` vertices may be touched and carry their 1-rings;
// the rest are the ring-only vertices those rings reach. The shaft passes through the user's trocar
// pivot, so the patch carries it and the client needs nothing else to find the contact. The grasp,
// when active, says which vertex the forceps hold and where the tool was when they closed on it.
// Units: m, N/m, N s/m.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/mesh/tet_mesh.h"

namespace cohaptic {

struct HomeSpringGrasp {
  int vertex = -1;                                          ///< grasped vertex; -1: none
  Eigen::Vector3d tool_at_grasp = Eigen::Vector3d::Zero();  ///< tool point when the jaws closed [m]

  bool active() const { return vertex >= 0; }
};

struct HomeSpringPatch {
  Eigen::Matrix3Xd rest_positions;  ///< per vertex: touchable ones first, then ring-only [m]
  int contact_vertex_count = 0;     ///< vertices 0 .. n-1 may be touched and carry 1-rings
  std::vector<Triangle> triangles;  ///< the touchable rest surface (corners < contact_vertex_count)
  std::vector<int> ring_offsets;    ///< vertex v's 1-ring: ring_vertices[ring_offsets[v] ..[v + 1])
  std::vector<int> ring_vertices;   ///< patch vertex indices
  std::vector<int> surface_vertex;  ///< per patch vertex, its index on the body's surface
  double home_stiffness = 0;        ///< k1 [N/m]
  double neighbour_stiffness = 0;   ///< k2 [N/m]
  double damping = 0;               ///< c [N s/m]: the dashpot beside each home spring (0: none)
  Eigen::Vector3d trocar_pivot = Eigen::Vector3d::Zero();  ///< the shaft passes here [m]
  HomeSpringGrasp grasp;

  int vertex_count() const { return static_cast<int>(rest_positions.cols()); }
  int triangle_count() const { return static_cast<int>(triangles.size()); }
  std::span<const int> ring(int vertex) const {
    const auto begin = static_cast<std::size_t>(ring_offsets[static_cast<std::size_t>(vertex)]);
    const auto end = static_cast<std::size_t>(ring_offsets[static_cast<std::size_t>(vertex) + 1]);
    return std::span<const int>(ring_vertices).subspan(begin, end - begin);
  }
  /// Bytes of the content as sent (the IR's size accounting).
  std::size_t size_bytes() const;
};

/// Throws Error naming the first thing wrong: sizes that disagree, an index out of range,
/// a vertex in its own ring or twice in it, a neighbour at the vertex's rest position, a
/// degenerate triangle, a stiffness that is not positive (k1) or negative (k2), a negative
/// damping, anything not finite, a grasp of a vertex that cannot be touched.
void validate_home_spring_patch(const HomeSpringPatch& patch);

/// The touchable vertex nearest `point` (the lowest index on a tie), e.g. the vertex the
/// forceps hold when they close at a grasp point. noexcept; -1 for a patch without any.
int nearest_touchable_vertex(const HomeSpringPatch& patch, const Eigen::Vector3d& point) noexcept;

}  // namespace cohaptic
