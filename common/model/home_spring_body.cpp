#include "common/model/home_spring_body.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>

#include "common/laparoscopy/tissue_grid.h"
#include "common/mesh/read_freesurfer.h"
#include "common/scene/load_scene.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

TriangleSurface tissue_surface(const HomeSpringObjectSpec& spec, double metres_per_unit) {
  if (spec.grid) return tissue_grid(*spec.grid);
  TriangleSurface surface = read_freesurfer_ascii(spec.surface_file);
  surface.vertices *= metres_per_unit;
  return surface;
}

// What a patch of it would be refused for (validate_home_spring_patch), said when the scene
// is loaded rather than when a tool first touches there. An open sheet is what a tissue is.
void check_tissue_surface(const TriangleSurface& surface) {
  for (int v = 0; v < surface.vertex_count(); ++v)
    if (!surface.vertices.col(v).allFinite())
      throw Error(fmt::format("the tissue surface's vertex {} is not finite", v));
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    const Triangle& tri = surface.triangles[t];
    for (const int v : tri)
      if (v < 0 || v >= surface.vertex_count())
        throw Error(fmt::format("the tissue surface's triangle {} names vertex {}, there are {}", t,
                                v, surface.vertex_count()));
    const Eigen::Vector3d a = surface.vertices.col(tri[0]), b = surface.vertices.col(tri[1]),
                          c = surface.vertices.col(tri[2]);
    if (!((b - a).cross(c - a).norm() > 0))
      throw Error(
          fmt::format("the tissue surface's triangle {} (vertices {}, {}, {}) is degenerate", t,
                      tri[0], tri[1], tri[2]));
  }
}

double longest_triangle_edge(const TriangleSurface& surface) {
  double longest = 0;
  for (const Triangle& tri : surface.triangles)
    for (int k = 0; k < 3; ++k)
      longest = std::max(
          longest, (surface.vertices.col(tri[k]) - surface.vertices.col(tri[(k + 1) % 3])).norm());
  return longest;
}

}  // namespace

HomeSpringBody build_home_spring_body(const std::string& name, const HomeSpringObjectSpec& spec,
                                      const std::string& where, double metres_per_unit) {
  HomeSpringBody body;
  body.name = name;
  body.spec = spec;
  try {
    body.surface = tissue_surface(spec, metres_per_unit);
    if (body.surface.triangles.empty()) throw Error("the tissue surface has no triangle");
    check_tissue_surface(body.surface);
    body.rings = vertex_rings(body.surface.triangles, body.surface.vertex_count());
    body.tree = AabbTree(body.surface.vertices, body.surface.triangles);
    body.display = make_tissue_display(body.surface.vertices, spec.display_radius,
                                       spec.display == TissueDisplayKind::polynomial
                                           ? DisplayDeformation::polynomial
                                           : DisplayDeformation::ffd_one_point);
  } catch (const SceneError&) {
    throw;
  } catch (const Error& e) {
    throw SceneError(fmt::format("{}: {}", where, e.what()));
  }
  body.longest_edge = longest_triangle_edge(body.surface);
  if (!(body.longest_edge > 0))
    throw SceneError(fmt::format("{}: the tissue surface's triangles have no extent", where));
  if (spec.patch_radius < body.longest_edge)
    throw SceneError(fmt::format(
        "{}.patch_radius: {} m is below the surface's longest edge ({} m): the patch around a "
        "contact vertex would miss triangles around it",
        where, spec.patch_radius, body.longest_edge));
  spdlog::info(
      "object '{}' (home spring): {} vertices, {} triangles, longest edge {:.3g} mm, k1 {:g} N/m, "
      "k2 {:g} N/m{}",
      name, body.surface.vertex_count(), body.surface.triangle_count(), 1000 * body.longest_edge,
      spec.home_stiffness, spec.neighbour_stiffness,
      spec.damping > 0 ? fmt::format(", damping c {:g} N s/m", spec.damping) : "");
  return body;
}

}  // namespace cohaptic
