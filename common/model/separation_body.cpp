#include "common/model/separation_body.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "common/model/compliance_setup.h"
#include "common/scene/load_scene.h"
#include "common/util/error.h"

namespace cohaptic {

void use_separation_field_cache(Scene& scene,
                                const std::optional<std::filesystem::path>& directory) {
  for (ObjectSpec& object : scene.objects)
    if (auto* separation = std::get_if<SeparationObjectSpec>(&object.body)) {
      separation->disk_cache = separation->disk_cache && directory.has_value();
      if (directory) separation->cache_directory = *directory;
    }
}

SeparationModel build_separation_body(const std::string& name, const SeparationObjectSpec& spec,
                                      double force_limit, const std::string& where) {
  SeparationModel body;
  body.name = name;
  body.spec = spec;
  SeparationSettings settings = spec.settings;
  settings.force_limit = std::min(settings.force_limit, force_limit);
  TwoLayerSetup setup;
  try {
    validate(spec.fields);
    const std::filesystem::path cache = !spec.disk_cache               ? std::filesystem::path{}
                                        : spec.cache_directory.empty() ? default_cache_directory()
                                                                       : spec.cache_directory;
    setup = make_two_layer_setup(spec.layers, spec.fields, settings, cache);
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
