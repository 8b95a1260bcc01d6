#include "support/cube_scene.h"

#include <fmt/format.h>

#include "common/scene/load_scene.h"

namespace cohaptic::testing {

CubeSceneOptions pressed_cube_options() {
  CubeSceneOptions cube;
  cube.divisions = 7;
  cube.youngs_modulus = 2.0e5;
  cube.touchable = "{surface: true}";
  cube.compliance = "{precompute: touchable, disk_cache: false}";
  cube.tools = "[{name: A}]";
  return cube;
}

std::string cube_scene_yaml(const CubeSceneOptions& o) {
  return fmt::format(
      R"(
units: mm
objects:
  - name: cube
    mesh: {{box: {{min: [-65, -65, -130], size: [130, 130, 130], divisions: [{0}, {0}, {0}]}}}}
    material: {{youngs_modulus: {1}, poisson_ratio: {2}}}
    fixed: [{{plane: {{point: [0, 0, -130], normal: [0, 0, 1]}}}}]
    touchable: [{3}]
    compliance: {7}
obstacles: [{4}]
tools: {5}
haptic: {{force_limit: {6}{8}}}
)",
      o.divisions, o.youngs_modulus, o.poisson_ratio, o.touchable, o.obstacles, o.tools,
      o.force_limit, o.compliance,
      o.contact_model.empty() ? std::string() : ", contact_model: " + o.contact_model);
}

CubeRig::CubeRig(const CubeSceneOptions& options) : CubeRig(cube_scene_yaml(options)) {}

CubeRig::CubeRig(const std::string& scene_yaml)
    : model(std::make_unique<Model>(build_model(parse_scene(scene_yaml, "cube.yaml")))),
      body(single_elastic_body(*model)),
      columns(
          std::make_unique<ComplianceColumns>(body.free_factor, body.dofs, body.surface.nodes)) {}

}  // namespace cohaptic::testing
