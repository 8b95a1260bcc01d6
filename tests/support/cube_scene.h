// The paper's cube as scene text, with the knobs tests and benchmarks turn.
#pragma once

#include <memory>
#include <string>

#include "common/fem/compliance.h"
#include "common/model/model.h"

namespace cohaptic::testing {

struct CubeSceneOptions {
  int divisions = 11;
  double youngs_modulus = 1.0e6;
  double poisson_ratio = 0.4;
  std::string touchable = "{plane: {point: [0, 0, 0], normal: [0, 0, 1]}}";
  std::string obstacles;  ///< YAML list items, e.g. "- {name: wall, plane: {...}}"
  std::string tools = "[{name: A}, {name: B}]";
  std::string compliance = "{precompute: on_demand, disk_cache: false}";
  double force_limit = 3.3;
  std::string contact_model;  ///< haptic.contact_model; empty: the scene's default for its tools
};

/// A 130 mm cube (z from -130 to 0 mm), rear face fixed, in millimetres.
std::string cube_scene_yaml(const CubeSceneOptions& options = {});

/// The small cube a lab session presses with one tool, open loop: its whole surface is
/// touchable and its compliance computed when the scene loads, so that the nodes step delay
/// holds need no columns computed at the first contact (which on a loaded machine could
/// stall the server past the client's fade age and split the stroke).
CubeSceneOptions pressed_cube_options();

/// The cube's model and its compliance columns over the whole surface (any node may be held).
struct CubeRig {
  std::unique_ptr<Model> model;
  const ElasticBody& body;  ///< the cube, model's only body
  std::unique_ptr<ComplianceColumns> columns;
  explicit CubeRig(const CubeSceneOptions& options = {});
  /// The same for scene text of the cube's shape (e.g. cube_scene_yaml with its mesh changed).
  explicit CubeRig(const std::string& scene_yaml);
};

}  // namespace cohaptic::testing
