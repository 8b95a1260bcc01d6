// SeparationObjectSpec: a scene object of `model: separation` (the separation-forces
// paper's two bodies sharing a triangulated interface), as parsed by
// common/scene/parse_separation.cpp: the two layers (the base held on its bottom face, the
// flap held where it goes on into tissue, two_layer_setup.h), the fields' settings, the
// fracture, laser and tissue settings (separation_settings.h, with the cited defaults), the
// instruments (which tools carry a laser fibre, how near jaws must close to grasp) and how
// often a user's IR is rebuilt. Units: SI (lengths already scaled by the scene's units).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "common/separation/separation_bodies.h"
#include "common/separation/separation_fields.h"
#include "common/separation/separation_settings.h"
#include "common/separation/separation_tool.h"

namespace cohaptic {

/// One scene tool's instrument on this body (tools not listed are plain forceps).
struct SeparationInstrumentSpec {
  std::string tool;  ///< the scene tool's name
  SeparationToolSettings settings;
};

struct SeparationObjectSpec {
  TwoLayerBoxes layers;
  FieldSettings fields;
  SeparationSettings settings;
  std::vector<SeparationInstrumentSpec> instruments;
  double grasp_reach = 1e-3;  ///< of the tools not listed [m]
  double ir_rate_hz = 50;     ///< at most this many IRs a second per user while its state changes
  bool disk_cache = true;     ///< keep the fitted fields in the cache directory
  /// Where (set by the program, e.g. the server's --cache-dir); empty: default_cache_directory().
  std::filesystem::path cache_directory;
};

}  // namespace cohaptic
