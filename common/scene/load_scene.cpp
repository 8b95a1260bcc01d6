#include "common/scene/load_scene.h"

#include "common/kinds/session_limits.h"
#include "common/mesh/mesh_limits.h"
#include "common/scene/parse_home_spring.h"
#include "common/scene/parse_interactions.h"
#include "common/scene/parse_mass_spring.h"
#include "common/scene/parse_mesh.h"
#include "common/scene/parse_node_selector.h"
#include "common/scene/parse_separation.h"
#include "common/util/yaml_cursor.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <fstream>
#include <set>
#include <sstream>

namespace cohaptic {
namespace {

[[noreturn]] void raise_scene_error(const std::string& file, int line, const std::string& message) {
  throw SceneError(line > 0 ? fmt::format("{}:{}: {}", file, line, message)
                            : fmt::format("{}: {}", file, message));
}

using Cursor = YamlCursor;

double metres_per(const Cursor& units) {
  const std::string u = units.choice({"m", "cm", "mm"});
  return u == "m" ? 1.0 : u == "cm" ? 0.01 : 0.001;
}

// The scene file's names of the tool shapes, in ToolShape's order.
constexpr std::array<const char*, 4> kToolShapeNames = {"point", "sphere", "probe", "forceps"};

const char* tool_shape_name(ToolShape shape) {
  return kToolShapeNames[static_cast<std::size_t>(shape)];
}

// `model: linear_elastic` (also the default): the keys of an FEM solid.
ElasticObjectSpec parse_elastic_object(const Cursor& c, double scale, const SceneFiles& files) {
  c.only_keys({"name", "model", "mesh", "material", "fixed", "touchable", "compliance"});
  ElasticObjectSpec object;
  object.mesh = parse_mesh(c.at("mesh"), scale, files);

  const Cursor material = c.at("material");
  material.only_keys({"model", "youngs_modulus", "poisson_ratio", "element"});
  if (auto model = material.find("model")) model->choice({"linear_elastic"});
  if (auto element = material.find("element"))
    object.material.formulation =
        element->choice({"linear_tet", "nodal_pressure_tet"}) == "linear_tet"
            ? ElementFormulation::linear_tet
            : ElementFormulation::nodal_pressure_tet;
  object.material.youngs_modulus =
      material.at("youngs_modulus").number_in(0, INFINITY, true, true, "a positive modulus in Pa");
  object.material.poisson_ratio = material.at("poisson_ratio")
                                      .number_in(-1, 0.5, true, true,
                                                 "a number in (-1, 0.5): 0.5 is incompressible, "
                                                 "which linear tetrahedra cannot represent");

  object.fixed = parse_fixed_regions(c.at("fixed"), scale);

  if (auto touchable = c.find("touchable")) {
    for (const Cursor& item : touchable->items()) {
      item.only_keys({"surface", "box", "plane", "nodes"});
      object.touchable.push_back(parse_node_selector(item, scale));
    }
  } else {
    NodeSelector whole;
    whole.where = c.location() + ".touchable (default: the whole surface)";
    object.touchable.push_back(whole);
  }

  if (auto compliance = c.find("compliance")) {
    compliance->only_keys({"precompute", "disk_cache"});
    if (auto precompute = compliance->find("precompute"))
      object.compliance.precompute_touchable =
          precompute->choice({"touchable", "on_demand"}) == "touchable";
    if (auto disk_cache = compliance->find("disk_cache"))
      object.compliance.disk_cache = disk_cache->boolean();
  }
  return object;
}

ObjectSpec parse_object(const Cursor& c, double scale, const SceneFiles& files) {
  if (!c.is_map()) c.fail("a map describing a deformable object");
  ObjectSpec object;
  object.where = c.location();
  object.name = c.at("name").text();
  const std::string model =
      c.find("model")
          ? c.at("model").choice({"linear_elastic", "mass_spring", "home_spring", "separation"})
          : "linear_elastic";
  if (model == "linear_elastic")
    object.body = parse_elastic_object(c, scale, files);
  else if (model == "mass_spring")
    object.body = parse_mass_spring_object(c, scale);
  else if (model == "home_spring")
    object.body = parse_home_spring_object(c, scale, files);
  else
    object.body = parse_separation_object(c, scale, files);
  return object;
}

ObstacleSpec parse_obstacle(const Cursor& c, double scale, const SceneFiles& files) {
  c.only_keys({"name", "surface", "plane"});
  ObstacleSpec obstacle;
  obstacle.name = c.at("name").text();
  const auto surface = c.find("surface");
  const auto plane = c.find("plane");
  if (static_cast<bool>(surface) == static_cast<bool>(plane))
    c.fail("exactly one of surface (a file) or plane");
  if (surface) {
    obstacle.surface_file = files.resolve(*surface, "surface file");
  } else {
    plane->only_keys({"point", "normal"});
    const Eigen::Vector3d normal = plane->at("normal").direction("a non-zero normal vector");
    obstacle.plane = std::make_pair(Eigen::Vector3d(plane->at("point").vec3() * scale), normal);
  }
  return obstacle;
}

ToolSpec parse_tool(const Cursor& c, double scale) {
  c.only_keys({"name", "shape", "radius", "trocar", "jaws"});
  ToolSpec tool;
  tool.name = c.at("name").text();
  if (auto shape = c.find("shape")) {
    const std::string name = shape->choice({"point", "sphere", "probe", "forceps"});
    tool.shape = static_cast<ToolShape>(
        std::find(kToolShapeNames.begin(), kToolShapeNames.end(), name) - kToolShapeNames.begin());
  }
  if (tool.shape == ToolShape::probe || tool.shape == ToolShape::forceps)
    tool.instrument = parse_instrument(c, scale, tool.shape == ToolShape::forceps);
  else if (auto trocar = c.find("trocar"))
    trocar->fail_message("only an instrument has a trocar (use shape: probe or shape: forceps)");
  else if (auto jaws = c.find("jaws"))
    jaws->fail_message("only forceps have jaws (use shape: forceps)");
  if (tool.shape == ToolShape::sphere)
    tool.radius = c.at("radius").number_in(0, INFINITY, true, true, "a positive radius") * scale;
  else if (auto radius = c.find("radius"))
    radius->fail_message(
        fmt::format("a {} tool has no radius (use shape: sphere)", tool_shape_name(tool.shape)));
  return tool;
}

HapticSettings parse_haptic(const Cursor& c) {
  c.only_keys({"rate_hz", "force_limit", "contact_model", "patch_rings", "boundary_truncation",
               "min_sim_rate_hz"});
  HapticSettings haptic;
  if (auto rate = c.find("rate_hz"))
    haptic.rate_hz = rate->number_in(1, 100000, false, false, "a rate from 1 to 100000 Hz");
  if (auto limit = c.find("force_limit"))
    haptic.force_limit_n =
        limit->number_in(0, 1000, true, false, "a force limit in N, in (0, 1000]");
  if (auto rings = c.find("patch_rings")) {
    const std::int64_t value = rings->integer();
    if (value < 0 || value > 4) rings->fail("an integer from 0 to 4");
    haptic.patch_rings = static_cast<int>(value);
  }
  if (auto rate = c.find("min_sim_rate_hz"))
    haptic.min_sim_rate_hz =
        rate->number_in(0, 100000, true, false, "a rate above 0 and at most 100000 Hz");
  if (auto truncation = c.find("boundary_truncation"))
    haptic.boundary_truncation = truncation->number_in(0, 1, false, true, "a fraction in [0, 1)");
  if (auto model = c.find("contact_model")) {
    const std::string name = model->choice({"translation", "point", "sphere"});
    haptic.contact_model = name == "translation" ? ContactModel::node_translation
                           : name == "point"     ? ContactModel::point_constraint
                                                 : ContactModel::sphere;
  }
  return haptic;
}

NetworkSettings parse_network(const Cursor& c, std::size_t tools) {
  c.only_keys({"max_participants"});
  NetworkSettings network;
  network.max_participants = static_cast<int>(tools);
  if (auto max = c.find("max_participants")) {
    const std::int64_t value = max->integer();
    if (value < 1 || value > static_cast<std::int64_t>(tools))
      max->fail(fmt::format("an integer from 1 to the number of tools ({})", tools));
    network.max_participants = static_cast<int>(value);
  }
  return network;
}

}  // namespace

Scene parse_scene(const std::string& yaml_text, const std::filesystem::path& file,
                  const SceneFileAccess& access) {
  const std::string file_name = file.string();
  const Cursor top(load_yaml(yaml_text, file_name, raise_scene_error), "", &file_name, 1,
                   raise_scene_error);
  if (!top.is_map()) top.fail("a map of scene settings");
  top.only_keys(
      {"name", "units", "objects", "interactions", "obstacles", "tools", "haptic", "network"});

  Scene scene;
  scene.file = file;
  scene.name = top.find("name") ? top.at("name").text() : file.stem().string();
  if (auto units = top.find("units")) {
    scene.metres_per_unit = metres_per(*units);
    scene.units = units->text();
  }
  const double scale = scene.metres_per_unit;
  const SceneFiles files{file.has_parent_path() ? file.parent_path() : std::filesystem::path("."),
                         access};

  const Cursor objects = top.at("objects");
  std::set<std::string> object_names;
  for (const Cursor& item : objects.items()) {
    scene.objects.push_back(parse_object(item, scale, files));
    if (!object_names.insert(scene.objects.back().name).second)
      item.at("name").fail("an object name not used before");
  }
  if (scene.objects.empty()) objects.fail("at least one object");
  if (auto interactions = top.find("interactions"))
    scene.interactions = parse_interactions(*interactions, scene.objects);

  if (auto obstacles = top.find("obstacles")) {
    std::set<std::string> obstacle_names;
    for (const Cursor& item : obstacles->items()) {
      scene.obstacles.push_back(parse_obstacle(item, scale, files));
      if (!obstacle_names.insert(scene.obstacles.back().name).second)
        item.at("name").fail("an obstacle name not used before");
    }
  }

  const Cursor tools = top.at("tools");
  std::set<std::string> tool_names;
  for (const Cursor& item : tools.items()) {
    scene.tools.push_back(parse_tool(item, scale));
    if (!tool_names.insert(scene.tools.back().name).second)
      item.at("name").fail("a tool name not used before");
  }
  if (scene.tools.empty()) tools.fail("at least one tool");
  if (scene.tools.size() > static_cast<std::size_t>(kMaxUsers))
    tools.fail(
        fmt::format("at most {} tools (one per user; the haptic loop holds that many)", kMaxUsers));
  const std::vector<Cursor> object_items = objects.items();
  for (std::size_t i = 0; i < scene.objects.size(); ++i)
    if (const auto* separation = std::get_if<SeparationObjectSpec>(&scene.objects[i].body))
      for (std::size_t j = 0; j < separation->instruments.size(); ++j)
        if (!tool_names.count(separation->instruments[j].tool))
          object_items[i].at("instruments").items()[j].at("tool").fail("the name of a scene tool");

  const std::optional<Cursor> haptic = top.find("haptic");
  if (haptic) scene.haptic = parse_haptic(*haptic);
  // The sphere model is the default when every tool is a sphere, and needs sphere tools.
  const std::optional<Cursor> contact_model = haptic ? haptic->find("contact_model") : std::nullopt;
  const auto point = std::find_if(scene.tools.begin(), scene.tools.end(), [](const ToolSpec& tool) {
    return tool.shape != ToolShape::sphere;
  });
  if (!contact_model && point == scene.tools.end())
    scene.haptic.contact_model = ContactModel::sphere;
  if (contact_model && scene.haptic.contact_model == ContactModel::sphere &&
      point != scene.tools.end())
    contact_model->fail_message(
        fmt::format("the sphere contact model needs sphere tools, and tool '{}' is a {} "
                    "(give it shape: sphere and a radius, or use translation or point)",
                    point->name, tool_shape_name(point->shape)));
  for (const InteractionSpec& interaction : scene.interactions)
    if (const auto front =
            std::find_if(scene.objects.begin(), scene.objects.end(),
                         [&](const ObjectSpec& o) { return o.name == interaction.front; });
        std::holds_alternative<ElasticObjectSpec>(front->body) &&
        scene.haptic.contact_model != ContactModel::node_translation)
      throw SceneError(fmt::format(
          "{}: the linear elastic front object '{}' presses on '{}' under the translation "
          "contact model only, and this scene's is '{}' (haptic: {{contact_model: translation}})",
          interaction.where, interaction.front, interaction.behind,
          contact_model_name(scene.haptic.contact_model)));
  scene.network.max_participants = static_cast<int>(scene.tools.size());
  if (auto network = top.find("network"))
    scene.network = parse_network(*network, scene.tools.size());
  return scene;
}

Scene load_scene(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in)
    throw SceneError(
        fmt::format("{}: cannot open the scene file: {}", file.string(), std::strerror(errno)));
  std::stringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), file);
}

}  // namespace cohaptic
