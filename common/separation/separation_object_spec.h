// SeparationObjectSpec: a scene object of `model: separation` (the separation-forces
// paper's two bodies sharing a triangulated interface), as parsed by
// common/scene/parse_separation.cpp: the two bodies (either generated layers, the base held
// on its bottom face and the flap where it goes on into tissue, separation_setup.h; or the
// user's own meshes with their supports, the interface found where their surfaces coincide),
// the fields' settings, the fracture, laser and tissue settings (separation_settings.h,
// with the cited defaults), the instruments (which tools carry a laser fibre, how near
// jaws must close to grasp) and how often a user's IR is rebuilt. Units: SI (lengths
// already scaled by the scene's units; a mesh file's coordinates are scaled when it is read).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "common/fem/mesh_spec.h"
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

/// One of the two bodies on the user's own mesh.
struct SeparationBodySpec {
  MeshSpec mesh;
  LinearElasticMaterial material;
  std::vector<FixedRegion> fixed;  ///< at least one: each body needs supports of its own
};

/// The two bodies on the user's own meshes. Their interface is every pair of boundary
/// triangles whose nodes coincide within `interface_tolerance` (find_interface); its rim
/// edges may start a crack unless both their nodes are selected by `sealed`.
struct SeparationMeshesSpec {
  SeparationBodySpec pulled;                  ///< B1, the body a tool pulls away
  SeparationBodySpec base;                    ///< B2, the body it is attached to
  std::optional<double> interface_tolerance;  ///< [m]; default: 1e-6 of the pulled mesh's size
  std::vector<NodeSelector> sealed;           ///< where the layers go on beyond the model
};

struct SeparationObjectSpec {
  std::variant<TwoLayerBoxes, SeparationMeshesSpec> bodies;
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
