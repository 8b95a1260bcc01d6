// The whole separation set-up of a scene object in one call: the two bodies, their
// interface (with its sealed rim), the fitted fields (from a disk cache when a directory
// is given) and the patch the haptic evaluation runs on. What a scene loader, the figures
// and the benchmarks share. Units: SI.
#pragma once

#include <filesystem>

#include "common/separation/separation_field_cache.h"
#include "common/separation/separation_patch.h"

namespace cohaptic {

struct SeparationSetup {
  SeparationBodies bodies;
  SeparationInterface interface;
  SeparationFields fields;
  FieldPrecomputeReport report;  ///< zero when the fields came from the cache
  bool fields_from_cache = false;
  SeparationPatch patch;
};

/// Fits the fields of `bodies` over `interface` (its rim already sealed where the layers go
/// on) and builds the patch. `cache_directory` empty: precompute without a cache.
SeparationSetup make_separation_setup(SeparationBodies bodies, SeparationInterface interface,
                                      const FieldSettings& field_settings,
                                      const SeparationSettings& settings,
                                      const std::filesystem::path& cache_directory = {});

/// The two stacked boxes (make_two_layer_boxes), their interface sealed at the pulled
/// layer's held end x = origin.x + a, then make_separation_setup.
SeparationSetup make_two_layer_setup(const TwoLayerBoxes& boxes,
                                     const FieldSettings& field_settings,
                                     const SeparationSettings& settings,
                                     const std::filesystem::path& cache_directory = {});

/// The patch node nearest `point` [m].
int nearest_patch_node(const SeparationPatch& patch, const Eigen::Vector3d& point);

}  // namespace cohaptic
