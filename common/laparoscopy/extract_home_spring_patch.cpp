#include "common/laparoscopy/extract_home_spring_patch.h"

#include <fmt/format.h>
#include <unordered_map>

#include "common/util/error.h"

namespace cohaptic {

HomeSpringPatch extract_home_spring_patch(const HomeSpringSurface& surface,
                                          const Eigen::Vector3d& centre, double radius,
                                          const HomeSpringConstants& constants,
                                          const Eigen::Vector3d& trocar_pivot) {
  const int surface_vertices = static_cast<int>(surface.rest_positions.cols());
  if (surface.rings.offsets.size() != static_cast<std::size_t>(surface_vertices) + 1)
    throw Error(fmt::format("home-spring patch: the rings cover {} vertices, the surface has {}",
                            static_cast<long>(surface.rings.offsets.size()) - 1, surface_vertices));
  const double radius2 = radius * radius;
  std::vector<char> touchable(static_cast<std::size_t>(surface_vertices), 0);
  std::vector<Triangle> region;
  for (const Triangle& tri : surface.triangles) {
    bool inside = true;
    for (const int v : tri)
      inside = inside && (surface.rest_positions.col(v) - centre).squaredNorm() <= radius2;
    if (!inside) continue;
    region.push_back(tri);
    for (const int v : tri) touchable[static_cast<std::size_t>(v)] = 1;
  }
  if (region.empty())
    throw Error(
        fmt::format("home-spring patch: no surface triangle lies within {} m of ({}, {}, {})",
                    radius, centre.x(), centre.y(), centre.z()));

  HomeSpringPatch patch;
  std::unordered_map<int, int> local;  // surface index -> patch index
  for (int v = 0; v < surface_vertices; ++v)
    if (touchable[static_cast<std::size_t>(v)]) {
      local.emplace(v, static_cast<int>(patch.surface_vertex.size()));
      patch.surface_vertex.push_back(v);
    }
  patch.contact_vertex_count = static_cast<int>(patch.surface_vertex.size());
  patch.ring_offsets.push_back(0);
  for (int i = 0; i < patch.contact_vertex_count; ++i) {
    for (const int j : surface.rings.ring(patch.surface_vertex[static_cast<std::size_t>(i)])) {
      const auto [where, added] = local.emplace(j, static_cast<int>(patch.surface_vertex.size()));
      if (added) patch.surface_vertex.push_back(j);
      patch.ring_vertices.push_back(where->second);
    }
    patch.ring_offsets.push_back(static_cast<int>(patch.ring_vertices.size()));
  }
  patch.rest_positions.resize(3, static_cast<Eigen::Index>(patch.surface_vertex.size()));
  for (std::size_t i = 0; i < patch.surface_vertex.size(); ++i)
    patch.rest_positions.col(static_cast<Eigen::Index>(i)) =
        surface.rest_positions.col(patch.surface_vertex[i]);
  patch.triangles.reserve(region.size());
  for (const Triangle& tri : region)
    patch.triangles.push_back({local.at(tri[0]), local.at(tri[1]), local.at(tri[2])});
  patch.home_stiffness = constants.home;
  patch.neighbour_stiffness = constants.neighbour;
  patch.damping = constants.damping;
  patch.trocar_pivot = trocar_pivot;
  validate_home_spring_patch(patch);
  return patch;
}

}  // namespace cohaptic
