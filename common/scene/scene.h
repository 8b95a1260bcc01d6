// Scene: the plain description of what to simulate, as loaded from a YAML scene file.
//
// Everything here is in SI units (lengths converted from the file's `units` on load;
// moduli in Pa, forces in N, rates in Hz). A Scene is validated when loaded (see
// load_scene.h) and compiled into a Model (model.h); only what it lists is built.
// The file format is documented in docs/scene-files.md, "Scene files".
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "common/fem/dof_map.h"
#include "common/fem/linear_elastic_material.h"
#include "common/kinds/body_kinds.h"
#include "common/kinds/contact_model.h"
#include "common/laparoscopy/home_spring_spec.h"
#include "common/mass_spring/mass_spring_spec.h"
#include "common/mesh/node_selector.h"
#include "common/fem/mesh_spec.h"
#include "common/separation/separation_object_spec.h"

namespace cohaptic {

/// probe and forceps are laparoscopic instruments (home_spring_spec.h): a shaft through a
/// trocar; on any other body kind their tip is a point.
enum class ToolShape { point, sphere, probe, forceps };

struct ComplianceSettings {
  bool precompute_touchable =
      true;                ///< whole touchable block up front (small meshes) or per node on demand
  bool disk_cache = true;  ///< persist computed columns, keyed by a content hash
};

/// `model: linear_elastic`: a solid of linear elastic tetrahedra, condensed for the haptic
/// clients (the haptic-interface-protocol paper's body).
struct ElasticObjectSpec {
  MeshSpec mesh;
  LinearElasticMaterial material;
  std::vector<FixedRegion> fixed;
  std::vector<NodeSelector>
      touchable;  ///< surface nodes a tool may press; triangles with all three
  ComplianceSettings compliance;
};

/// What the scene file says of a body (`model:` names its kind): one alternative per body
/// kind (common/kinds/body_kinds.h).
using BodySpec = PerKind<ForKind<LinearElasticKind, ElasticObjectSpec>,
                         ForKind<MassSpringKind, MassSpringObjectSpec>,
                         ForKind<HomeSpringKind, HomeSpringObjectSpec>,
                         ForKind<SeparationKind, SeparationObjectSpec>>::variant;

/// A deformable object of the scene: its name (unique in the scene) and its model's spec.
struct ObjectSpec {
  std::string name;
  BodySpec body;
  std::string where;  ///< "file:line: objects[i]", for messages
};

/// A rigid surface: a triangle surface file (FreeSurfer .asc) or an infinite plane.
struct ObstacleSpec {
  std::string name;
  std::filesystem::path surface_file;
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> plane;  ///< point [m], unit normal
};

struct ToolSpec {
  std::string name;
  ToolShape shape = ToolShape::point;
  double radius = 0;                         ///< [m], > 0 for a sphere
  std::optional<InstrumentSpec> instrument;  ///< set exactly for probe and forceps
};

struct HapticSettings {
  double rate_hz = 1000;
  double force_limit_n = 3.3;  ///< the PHANToM Omni's peak force
  ContactModel contact_model = ContactModel::node_translation;
  int patch_rings = 1;  ///< rings of neighbouring triangles in each IR's contact patch
  /// B truncation threshold in [0, 1): held nodes coupled to the contact rows more weakly
  /// than this fraction of the strongest are left out of the IR (0: none).
  double boundary_truncation = 0;
  /// The simulation's step rate below which the session is unhealthy [Hz]: slower, the IRs
  /// (P1) or forces (P0) the users feel go stale, whether the machine starved the server or
  /// a study capped it (--sim-rate-hz).
  double min_sim_rate_hz = 20;
};

/// How the session is served.
struct NetworkSettings {
  /// Users that may be joined at once; beyond it a join is refused ("session_full"). At
  /// most the number of tools (one slot per tool), which is also the default.
  int max_participants = 0;
};

/// Two objects that press on each other (the several-objects paper): the front object's
/// nodes collide with the behind object's surface, which is displaced to hold them and
/// pushes back. A mass-spring or a linear elastic front on a linear elastic behind object.
struct InteractionSpec {
  std::string front;   ///< object name (model: mass_spring or linear_elastic)
  std::string behind;  ///< object name (model: linear_elastic)
  std::string where;   ///< file:line of the entry, for errors
};

struct Scene {
  std::filesystem::path file;  ///< where it was loaded from (empty if built in code)
  std::string name;
  std::string units = "m";  ///< the length unit of the file
  double metres_per_unit = 1;
  std::vector<ObjectSpec> objects;  ///< at least one; the tools may press any of them
  std::vector<InteractionSpec> interactions;
  std::vector<ObstacleSpec> obstacles;
  std::vector<ToolSpec> tools;
  HapticSettings haptic;
  NetworkSettings network;  ///< max_participants resolved on load (never 0 after load_scene)
};

/// The scene's only object as an FEM object, for the tools that vary or read one FEM
/// object's settings (the trade-off, the probe). Throws Error naming the scene file when it
/// has several objects or its object is of another model.
const ElasticObjectSpec& single_elastic_object(const Scene& scene);
ElasticObjectSpec& single_elastic_object(Scene& scene);

}  // namespace cohaptic
