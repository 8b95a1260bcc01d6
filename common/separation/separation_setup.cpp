#include "common/separation/separation_setup.h"

#include <limits>

namespace cohaptic {

SeparationSetup make_separation_setup(SeparationBodies bodies, SeparationInterface interface,
                                      const FieldSettings& field_settings,
                                      const SeparationSettings& settings,
                                      const std::filesystem::path& cache_directory) {
  SeparationSetup setup;
  setup.bodies = std::move(bodies);
  setup.interface = std::move(interface);
  if (cache_directory.empty()) {
    setup.fields =
        precompute_separation_fields(setup.bodies, setup.interface, field_settings, &setup.report);
  } else {
    CachedSeparationFields cached =
        cached_separation_fields(cache_directory, setup.bodies, setup.interface, field_settings);
    setup.fields = std::move(cached.fields);
    setup.report = cached.report;
    setup.fields_from_cache = cached.from_cache;
  }
  setup.patch = make_separation_patch(setup.interface, setup.fields, settings);
  return setup;
}

SeparationSetup make_two_layer_setup(const TwoLayerBoxes& boxes,
                                     const FieldSettings& field_settings,
                                     const SeparationSettings& settings,
                                     const std::filesystem::path& cache_directory) {
  SeparationBodies bodies = make_two_layer_boxes(boxes);
  const double spacing = boxes.size.minCoeff() / boxes.divisions.maxCoeff();
  SeparationInterface interface = find_interface(bodies, 1e-6 * spacing);
  const double end = boxes.origin.x() + boxes.size.x() - 1e-6 * spacing;
  seal_rim_edges(interface, [&](int node) { return interface.positions(0, node) > end; });
  return make_separation_setup(std::move(bodies), std::move(interface), field_settings, settings,
                               cache_directory);
}

int nearest_patch_node(const SeparationPatch& patch, const Eigen::Vector3d& point) {
  int best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (int n = 0; n < patch.node_count(); ++n) {
    const double distance = (patch.positions.col(n) - point).squaredNorm();
    if (distance < best_distance) {
      best = n;
      best_distance = distance;
    }
  }
  return best;
}

}  // namespace cohaptic
