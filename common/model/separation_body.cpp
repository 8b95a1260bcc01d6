#include "common/model/separation_body.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <bit>
#include <utility>

#include "common/mesh/boundary_surface.h"
#include "common/mesh/mesh_checks.h"
#include "common/model/compliance_setup.h"
#include "common/model/elastic_body.h"
#include "common/model/load_mesh.h"
#include "common/scene/load_scene.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

// One body on the user's mesh, with its supports; `surface` receives its boundary.
SeparationBody build_separating_body(const SeparationBodySpec& spec, double metres_per_unit,
                                     const std::string& where, BoundarySurface& surface) {
  SeparationBody body;
  validate(spec.material);
  body.material = spec.material;
  body.mesh = load_mesh(spec.mesh, metres_per_unit);
  MeshCheckReport report = check_tet_mesh(body.mesh);
  for (const std::string& note : report.notes) spdlog::info("{} mesh: {}", where, note);
  for (const std::string& warning : report.warnings) spdlog::warn("{} mesh: {}", where, warning);
  surface = extract_boundary_surface(body.mesh);
  body.fixed_axes.assign(static_cast<std::size_t>(body.mesh.node_count()), 0);
  for (const FixedRegion& region : spec.fixed)
    for (int node : select_nodes(region.nodes, body.mesh, surface, false))
      body.fixed_axes[node] = static_cast<AxisMask>(body.fixed_axes[node] | region.axes);
  return body;
}

// The bodies on the user's meshes and their interface, its rim sealed where `sealed` says.
std::pair<SeparationBodies, SeparationInterface> bodies_on_meshes(const SeparationMeshesSpec& spec,
                                                                  double metres_per_unit,
                                                                  const std::string& where) {
  SeparationBodies bodies;
  BoundarySurface pulled_surface, base_surface;
  bodies.pulled =
      build_separating_body(spec.pulled, metres_per_unit, where + ".pulled", pulled_surface);
  bodies.base = build_separating_body(spec.base, metres_per_unit, where + ".base", base_surface);
  const TetMesh& pulled = bodies.pulled.mesh;
  const double size =
      (pulled.nodes.rowwise().maxCoeff() - pulled.nodes.rowwise().minCoeff()).norm();
  SeparationInterface interface =
      find_interface(bodies, spec.interface_tolerance.value_or(1e-6 * size));
  std::vector<bool> sealed(static_cast<std::size_t>(pulled.node_count()), false);
  for (const NodeSelector& selector : spec.sealed)
    for (int node : select_nodes(selector, pulled, pulled_surface, true)) sealed[node] = true;
  const auto open_rim_edges = [&interface] {
    int count = 0;
    for (std::uint8_t bits : interface.open_rim) count += std::popcount(bits);
    return count;
  };
  const int rim = open_rim_edges();
  seal_rim_edges(interface, [&](int node) { return sealed[interface.pulled_nodes[node]]; });
  const int open = open_rim_edges();
  spdlog::info("{}: interface of {} nodes and {} triangles; {} of its {} rim edges sealed", where,
               interface.node_count(), interface.triangle_count(), rim - open, rim);
  if (open == 0)
    spdlog::warn("{}: every rim edge of the interface is sealed: only a laser can start a crack",
                 where);
  return {std::move(bodies), std::move(interface)};
}

}  // namespace

void use_separation_field_cache(Scene& scene,
                                const std::optional<std::filesystem::path>& directory) {
  for (ObjectSpec& object : scene.objects)
    if (auto* separation = std::get_if<SeparationObjectSpec>(&object.body)) {
      separation->disk_cache = separation->disk_cache && directory.has_value();
      if (directory) separation->cache_directory = *directory;
    }
}

SeparationModel build_separation_body(const std::string& name, const SeparationObjectSpec& spec,
                                      double force_limit, double metres_per_unit,
                                      const std::string& where) {
  SeparationModel body;
  body.name = name;
  body.spec = spec;
  SeparationSettings settings = spec.settings;
  settings.force_limit = std::min(settings.force_limit, force_limit);
  SeparationSetup setup;
  try {
    validate(spec.fields);
    const std::filesystem::path cache = !spec.disk_cache               ? std::filesystem::path{}
                                        : spec.cache_directory.empty() ? default_cache_directory()
                                                                       : spec.cache_directory;
    if (const auto* layers = std::get_if<TwoLayerBoxes>(&spec.bodies)) {
      setup = make_two_layer_setup(*layers, spec.fields, settings, cache);
    } else {
      auto [bodies, interface] =
          bodies_on_meshes(std::get<SeparationMeshesSpec>(spec.bodies), metres_per_unit, where);
      setup = make_separation_setup(std::move(bodies), std::move(interface), spec.fields, settings,
                                    cache);
    }
  } catch (const SceneError&) {
    throw;
  } catch (const Error& e) {
    throw SceneError(fmt::format("{}: {}", where, e.what()));
  }
  body.bodies = std::move(setup.bodies);
  body.interface = std::move(setup.interface);
  body.report = setup.report;
  body.fields_from_cache = setup.fields_from_cache;
  body.patch = std::make_shared<const SeparationPatch>(std::move(setup.patch));
  spdlog::info(
      "separation body '{}': {} interface nodes, {} triangles, fields of degree {} {} ({:.2f} s)",
      name, body.patch->node_count(), body.patch->triangle_count(), body.patch->degree,
      body.fields_from_cache ? "from the cache" : "fitted to the FEM", body.report.total_seconds());
  body.plateau = plateau_reach(*body.patch);
  if (const std::string warning = plateau_warning(body.plateau, body.patch->normal_length);
      !warning.empty())
    spdlog::warn("{}: {}", where, warning);
  return body;
}

}  // namespace cohaptic
