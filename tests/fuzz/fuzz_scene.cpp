// Fuzz target: the scene loader (common/scene/load_scene.h), on the text of a scene file
// that sits in the repository's scenes/ directory (so its relative mesh paths resolve to
// real files).
//
// Input: the YAML text. Properties:
//   - parse_scene() either returns a scene or throws cohaptic::Error (SceneError) naming
//     the file: no exception of the YAML library, or anything else, escapes;
//   - a scene accepted holds what the format promises: a unit scale; objects, each body
//     checked by its kind (linear_elastic: a finite positive modulus, a Poisson ratio in
//     (-1, 0.5), box meshes of positive size; mass_spring: a finite tube of positive radius,
//     two sections or more, a unit `up`, finite positive modulus and density; separation:
//     finite positive layers with cells, fracture/laser/tissue/field settings that validate);
//     tools; plane normals of unit length; a
//     haptic rate in [1, 100000] Hz and a force limit in (0, 1000] N.
#include <cmath>
#include <cstdint>
#include <string>
#include <variant>

#include "common/mass_spring/mass_spring_spec.h"
#include "common/scene/load_scene.h"
#include "common/util/error.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using namespace cohaptic;
using fuzz::require;

void require_unit(const Eigen::Vector3d& normal) {
  require(normal.allFinite() && std::abs(normal.norm() - 1) < 1e-9,
          "an accepted direction is a unit vector");
}

void require_valid(const ElasticObjectSpec& object) {
  const LinearElasticMaterial& material = object.material;
  require(std::isfinite(material.youngs_modulus) && material.youngs_modulus > 0,
          "the modulus is positive and finite");
  require(material.poisson_ratio > -1 && material.poisson_ratio < 0.5,
          "the Poisson ratio is in (-1, 0.5)");
  if (object.mesh.box) {
    require(object.mesh.box->size.allFinite() && (object.mesh.box->size.array() > 0).all(),
            "a box has a size");
    require(object.mesh.box->min_corner.allFinite(), "a box has a corner");
  }
  for (const FixedRegion& region : object.fixed)
    if (region.nodes.kind == NodeSelector::Kind::plane) require_unit(region.nodes.plane_normal);
  for (const NodeSelector& selector : object.touchable)
    if (selector.kind == NodeSelector::Kind::plane) require_unit(selector.plane_normal);
}

void require_valid(const MassSpringObjectSpec& object) {
  for (const NodeSelector& selector : object.fixed)
    if (selector.kind == NodeSelector::Kind::plane) require_unit(selector.plane_normal);
  if (object.lattice) {
    require((object.lattice->size.array() > 0).all() && object.lattice->size.allFinite(),
            "a lattice has a size");
    require((object.lattice->divisions.array() >= 1).all(), "a lattice has divisions");
    require(object.lattice->spring_stiffness > 0 && object.lattice->node_mass > 0,
            "a lattice has springs and masses");
    return;
  }
  require(object.tube.centre_line.size() >= 2, "a tube has a centre line");
  for (const Eigen::Vector3d& point : object.tube.centre_line)
    require(point.allFinite(), "the centre line is finite");
  require(std::isfinite(object.tube.radius) && object.tube.radius > 0, "a tube has a radius");
  require(object.tube.sections >= 2, "a tube has two sections or more");
  require_unit(object.tube.up);
  require(std::isfinite(object.material.youngs_modulus) && object.material.youngs_modulus > 0,
          "the modulus is positive and finite");
  require(std::isfinite(object.material.density) && object.material.density > 0,
          "the density is positive and finite");
}

void require_valid(const HomeSpringObjectSpec& object) {
  require(!object.surface_file.empty() != object.grid.has_value(),
          "a tissue has a surface file or a grid");
  if (object.grid) {
    require(object.grid->min.allFinite() && object.grid->size.allFinite() &&
                (object.grid->size.array() > 0).all(),
            "a grid has a corner and a size");
    require((object.grid->divisions.array() >= 1).all(), "a grid has cells");
  }
  require(std::isfinite(object.home_stiffness) && object.home_stiffness > 0,
          "k1 is positive and finite");
  require(std::isfinite(object.neighbour_stiffness) && object.neighbour_stiffness >= 0,
          "k2 is finite and not negative");
  require(std::isfinite(object.patch_radius) && object.patch_radius > 0,
          "the patch radius is positive");
  require(std::isfinite(object.display_radius) && object.display_radius > 0,
          "the display radius is positive");
}

void require_valid(const TwoLayerBoxes& layers) {
  require(layers.origin.allFinite(), "the layers' origin is finite");
  require(layers.size.allFinite() && (layers.size.array() > 0).all(),
          "the layers have a finite positive size");
  require(std::isfinite(layers.pulled_thickness) && layers.pulled_thickness > 0 &&
              std::isfinite(layers.base_thickness) && layers.base_thickness > 0,
          "the layers have finite positive thicknesses");
  require(
      (layers.divisions.array() >= 1).all() && layers.pulled_layers >= 1 && layers.base_layers >= 1,
      "the layers have cells");
}

void require_valid(const SeparationMeshesSpec& meshes) {
  for (const SeparationBodySpec* body : {&meshes.pulled, &meshes.base}) {
    require(!body->fixed.empty(), "each separating body has supports");
    require(std::isfinite(body->material.youngs_modulus) && body->material.youngs_modulus > 0,
            "each separating body's modulus is positive");
  }
  require(!meshes.interface_tolerance ||
              (std::isfinite(*meshes.interface_tolerance) && *meshes.interface_tolerance > 0),
          "the interface tolerance is a positive length");
}

void require_valid(const SeparationObjectSpec& object) {
  std::visit([](const auto& bodies) { require_valid(bodies); }, object.bodies);
  bool settings_valid = true;
  try {
    validate(object.settings);
    validate(object.fields);
  } catch (const Error&) {
    settings_valid = false;
  }
  require(settings_valid,
          "an accepted separation object's fracture, laser, tissue and field settings are valid");
  for (const SeparationInstrumentSpec& instrument : object.instruments)
    require(std::isfinite(instrument.settings.grasp_reach) && instrument.settings.grasp_reach >= 0,
            "a grasp reach is a length");
}

void require_valid(const Scene& scene) {
  require(std::isfinite(scene.metres_per_unit) && scene.metres_per_unit > 0,
          "the unit scale is positive");
  require(!scene.objects.empty(), "a scene has objects");
  for (const ObjectSpec& object : scene.objects)
    std::visit([](const auto& body) { require_valid(body); }, object.body);
  require(!scene.tools.empty(), "a scene has tools");
  for (const ToolSpec& tool : scene.tools) {
    require(tool.shape != ToolShape::sphere || (std::isfinite(tool.radius) && tool.radius > 0),
            "a sphere has a radius");
    const bool instrument = tool.shape == ToolShape::probe || tool.shape == ToolShape::forceps;
    require(instrument == tool.instrument.has_value(), "exactly the instruments have a trocar");
    if (tool.instrument) {
      require(tool.instrument->trocar.allFinite(), "a trocar is finite");
      require_unit(tool.instrument->opening);
      require(tool.instrument->open_angle > 0 && tool.instrument->open_angle < M_PI / 2,
              "the jaws open below 90 degrees");
      require(tool.instrument->closing_step > 0 &&
                  tool.instrument->closing_step <= tool.instrument->open_angle,
              "the jaws close in positive steps");
    }
  }
  for (const ObstacleSpec& obstacle : scene.obstacles)
    if (obstacle.plane) require_unit(obstacle.plane->second);
  require(scene.haptic.rate_hz >= 1 && scene.haptic.rate_hz <= 100000,
          "the haptic rate is in range");
  require(scene.haptic.force_limit_n > 0 && scene.haptic.force_limit_n <= 1000,
          "the force limit is in range");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path file =
      std::filesystem::path(COHAPTIC_SOURCE_DIR) / "scenes" / "fuzzed.yaml";
  try {
    require_valid(parse_scene(std::string(reinterpret_cast<const char*>(data), size), file));
  } catch (const Error&) {
  }
  return 0;
}
