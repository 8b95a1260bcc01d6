#include "common/separation/two_layer_setup.h"

#include <limits>

namespace cohaptic {

TwoLayerSetup make_two_layer_setup(const TwoLayerBoxes& boxes, const FieldSettings& field_settings,
                                   const SeparationSettings& settings,
                                   const std::filesystem::path& cache_directory) {
  TwoLayerSetup setup;
  setup.bodies = make_two_layer_boxes(boxes);
  const double spacing = boxes.size.minCoeff() / boxes.divisions.maxCoeff();
  setup.interface = find_interface(setup.bodies, 1e-6 * spacing);
  const double end = boxes.size.x() - 1e-6 * spacing;
  seal_rim_edges(setup.interface,
                 [end](const Eigen::Vector3d& midpoint) { return midpoint.x() > end; });
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
