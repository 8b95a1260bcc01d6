#include "common/laparoscopy/home_spring_patch.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fmt/format.h>
#include <unordered_set>

#include "common/util/error.h"

namespace cohaptic {
namespace {

[[noreturn]] void fail(const std::string& what) { throw Error("home-spring patch: " + what); }

void check_rings(const HomeSpringPatch& patch) {
  const int n = patch.contact_vertex_count;
  if (patch.ring_offsets.size() != static_cast<std::size_t>(n) + 1)
    fail(fmt::format("ring_offsets has {} entries, expected contact_vertex_count + 1 = {}",
                     patch.ring_offsets.size(), n + 1));
  if (patch.ring_offsets.front() != 0)
    fail(fmt::format("ring_offsets[0] is {}, expected 0", patch.ring_offsets.front()));
  if (patch.ring_offsets.back() != static_cast<int>(patch.ring_vertices.size()))
    fail(fmt::format("ring_offsets ends at {}, but ring_vertices has {} entries",
                     patch.ring_offsets.back(), patch.ring_vertices.size()));
  // Every offset in order before any ring is read: a later decrease would let an earlier
  // ring run past ring_vertices.
  for (int v = 0; v < n; ++v)
    if (patch.ring_offsets[static_cast<std::size_t>(v) + 1] <
        patch.ring_offsets[static_cast<std::size_t>(v)])
      fail(fmt::format("ring_offsets decrease at vertex {}", v));
  for (int v = 0; v < n; ++v) {
    const std::span<const int> ring = patch.ring(v);
    if (ring.empty()) fail(fmt::format("touchable vertex {} has an empty 1-ring", v));
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const int j = ring[i];
      if (j < 0 || j >= patch.vertex_count())
        fail(fmt::format("vertex {}'s 1-ring names vertex {}, but there are {} vertices", v, j,
                         patch.vertex_count()));
      if (j == v) fail(fmt::format("vertex {} is in its own 1-ring", v));
      if (std::find(ring.begin(), ring.begin() + static_cast<std::ptrdiff_t>(i), j) !=
          ring.begin() + static_cast<std::ptrdiff_t>(i))
        fail(fmt::format("vertex {}'s 1-ring names vertex {} twice", v, j));
      if (!((patch.rest_positions.col(j) - patch.rest_positions.col(v)).norm() > 0))
        fail(fmt::format(
            "vertex {}'s neighbour {} is at its rest position (spring of rest length 0)", v, j));
    }
  }
}

void check_triangles(const HomeSpringPatch& patch) {
  if (patch.triangles.empty()) fail("no triangles");
  for (std::size_t t = 0; t < patch.triangles.size(); ++t) {
    const Triangle& tri = patch.triangles[t];
    for (const int v : tri)
      if (v < 0 || v >= patch.contact_vertex_count)
        fail(fmt::format("triangle {} names vertex {}, but only vertices 0..{} may be touched", t,
                         v, patch.contact_vertex_count - 1));
    const Eigen::Vector3d a = patch.rest_positions.col(tri[0]);
    const Eigen::Vector3d ab = patch.rest_positions.col(tri[1]) - a,
                          ac = patch.rest_positions.col(tri[2]) - a;
    if (!(ab.cross(ac).norm() > 1e-12 * ab.norm() * ac.norm()))
      fail(fmt::format("triangle {} is degenerate", t));
  }
}

}  // namespace

void validate_home_spring_patch(const HomeSpringPatch& patch) {
  const int m = patch.vertex_count();
  if (patch.contact_vertex_count < 1 || patch.contact_vertex_count > m)
    fail(fmt::format("contact_vertex_count is {}, expected 1..{} (the number of vertices)",
                     patch.contact_vertex_count, m));
  for (int v = 0; v < m; ++v)
    if (!patch.rest_positions.col(v).allFinite())
      fail(fmt::format("rest position of vertex {} is not finite", v));
  if (patch.surface_vertex.size() != static_cast<std::size_t>(m))
    fail(fmt::format("surface_vertex has {} entries, expected one per vertex ({})",
                     patch.surface_vertex.size(), m));
  std::unordered_set<int> seen;
  for (int v = 0; v < m; ++v) {
    const int s = patch.surface_vertex[static_cast<std::size_t>(v)];
    if (s < 0) fail(fmt::format("surface_vertex[{}] is {}, expected a surface index >= 0", v, s));
    if (!seen.insert(s).second)
      fail(fmt::format("surface vertex {} appears twice (patch vertex {})", s, v));
  }
  check_rings(patch);
  check_triangles(patch);
  if (!(patch.home_stiffness > 0) || !std::isfinite(patch.home_stiffness))
    fail(fmt::format("home_stiffness (k1) is {} N/m, expected positive and finite",
                     patch.home_stiffness));
  if (!(patch.neighbour_stiffness >= 0) || !std::isfinite(patch.neighbour_stiffness))
    fail(fmt::format("neighbour_stiffness (k2) is {} N/m, expected >= 0 and finite",
                     patch.neighbour_stiffness));
  if (!(patch.damping >= 0) || !std::isfinite(patch.damping))
    fail(fmt::format("damping (c) is {} N s/m, expected >= 0 and finite", patch.damping));
  if (!patch.trocar_pivot.allFinite()) fail("trocar_pivot is not finite");
  if (patch.grasp.vertex < -1 || patch.grasp.vertex >= patch.contact_vertex_count)
    fail(fmt::format("grasp names vertex {}, expected -1 (none) or a touchable vertex 0..{}",
                     patch.grasp.vertex, patch.contact_vertex_count - 1));
  if (!patch.grasp.tool_at_grasp.allFinite()) fail("grasp.tool_at_grasp is not finite");
}

std::size_t HomeSpringPatch::size_bytes() const {
  constexpr std::size_t kScalars =
      (3 + 3 + 3) * sizeof(double) + 2 * sizeof(std::int32_t);  // k1, k2, c, pivot, grasp
  const auto vertices = static_cast<std::size_t>(vertex_count());
  return kScalars + vertices * (3 * sizeof(double) + sizeof(std::int32_t)) +
         (triangles.size() * 3 + ring_offsets.size() + ring_vertices.size()) * sizeof(std::int32_t);
}

int nearest_touchable_vertex(const HomeSpringPatch& patch, const Eigen::Vector3d& point) noexcept {
  int nearest = -1;
  double nearest2 = 0;
  for (int v = 0; v < std::min(patch.contact_vertex_count, patch.vertex_count()); ++v) {
    const double d2 = (patch.rest_positions.col(v) - point).squaredNorm();
    if (nearest < 0 || d2 < nearest2) {
      nearest = v;
      nearest2 = d2;
    }
  }
  return nearest;
}

}  // namespace cohaptic
