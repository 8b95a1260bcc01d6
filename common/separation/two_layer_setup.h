// The whole separation set-up of a two-layer scene in one call: the two boxes, their
// interface (sealed where the pulled layer goes on into tissue, at x = a), the fitted
// fields (from a disk cache when a directory is given) and the patch the haptic
// evaluation runs on. What a scene loader, the figures and the benchmarks share.
#pragma once

#include <filesystem>

#include "common/separation/separation_field_cache.h"
#include "common/separation/separation_patch.h"

namespace cohaptic {

struct TwoLayerSetup {
  SeparationBodies bodies;
  SeparationInterface interface;
  SeparationFields fields;
  FieldPrecomputeReport report;  ///< zero when the fields came from the cache
  bool fields_from_cache = false;
  SeparationPatch patch;
};

/// `cache_directory` empty: precompute without a cache.
TwoLayerSetup make_two_layer_setup(const TwoLayerBoxes& boxes, const FieldSettings& field_settings,
                                   const SeparationSettings& settings,
                                   const std::filesystem::path& cache_directory = {});

/// The patch node nearest `point` [m].
int nearest_patch_node(const SeparationPatch& patch, const Eigen::Vector3d& point);

}  // namespace cohaptic
