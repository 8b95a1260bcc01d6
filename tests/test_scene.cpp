// Scene loading and validation (common/scene/load_scene.h) and compiling a scene into a
// Model (common/model/model.h): the shipped cube scene, error messages that name the
// file, line and key path, per-axis fixing and selectors that select nothing, and the
// mass-spring objects (`model: mass_spring`): the noodle scenes and their errors.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "common/haptics/trajectory.h"
#include "common/kinds/session_limits.h"
#include "common/mesh/box_mesher.h"
#include "common/model/model.h"
#include "common/mass_spring/tube_network.h"
#include "common/mesh/mesh_limits.h"
#include "common/scene/load_scene.h"
#include "common/separation/separation_bodies.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

// A valid scene in block style, so that every value sits on its own line. Tests derive
// malformed scenes from it by replacing one line (or block) and expect the message to
// name the line the replacement is on, counted here independently of the parser.
const std::string kBaseScene = R"(name: block_scene
units: mm
objects:
  - name: block
    mesh:
      box:
        min: [0, 0, 0]
        size: [10, 10, 10]
        divisions: [2, 2, 2]
    material:
      model: linear_elastic
      youngs_modulus: 1000
      poisson_ratio: 0.3
    fixed:
      - plane:
          point: [0, 0, 0]
          normal: [0, 0, 1]
        axes: xyz
    touchable:
      - plane:
          point: [0, 0, 10]
          normal: [0, 0, 1]
tools:
  - name: A
    shape: point
haptic:
  rate_hz: 1000
)";

// Not created: parse_scene only names it (and resolves relative mesh paths against it).
const std::string kSceneFile = "/nonexistent-cohaptic-test/scenes/bad_scene.yaml";

/// `text` with the first occurrence of `from` replaced by `to` (which must exist).
std::string replaced(const std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test setup: '" << from << "' is not in the scene";
  if (at == std::string::npos) return text;
  std::string out = text;
  out.replace(at, from.size(), to);
  return out;
}

/// 1-based number of the line holding the first occurrence of `needle`.
int line_of(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << "test setup: '" << needle << "' is not in the scene";
  if (at == std::string::npos) return -1;
  return 1 + static_cast<int>(
                 std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

std::optional<std::string> parse_error(const std::string& text) {
  try {
    parse_scene(text, kSceneFile);
  } catch (const SceneError& e) {
    return std::string(e.what());
  }
  return std::nullopt;
}

struct BadScene {
  const char* what;
  std::string text;
  std::string line_needle;             // the line the message must name
  std::vector<std::string> fragments;  // all must appear in the message
};

void expect_scene_error(const BadScene& bad) {
  SCOPED_TRACE(bad.what);
  const auto message = parse_error(bad.text);
  ASSERT_TRUE(message.has_value()) << "no SceneError for:\n" << bad.text;
  const std::string location =
      kSceneFile + ":" + std::to_string(line_of(bad.text, bad.line_needle)) + ":";
  EXPECT_EQ(message->rfind(location, 0), 0u)
      << "message: " << *message << "\nexpected it to start with " << location;
  for (const std::string& fragment : bad.fragments)
    EXPECT_NE(message->find(fragment), std::string::npos)
        << "message: " << *message << "\nlacks: " << fragment;
}

bool near(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(b)); }

TEST(SceneLoad, BaseSceneOfTheseTestsIsValid) {
  // Guards the error tests below: each of them differs from this scene in one place only.
  const Scene scene = parse_scene(kBaseScene, kSceneFile);
  EXPECT_EQ(scene.name, "block_scene");
  EXPECT_DOUBLE_EQ(single_elastic_object(scene).mesh.box->size.x(), 0.010);
  const Model model = build_model(scene);
  const ElasticBody& body = single_elastic_body(model);
  EXPECT_EQ(body.mesh.node_count(), 27);
}

TEST(SceneLoad, CubeSceneFieldsInSIUnits) {
  const Scene scene = load_scene(testing::source_path("scenes/cube.yaml"));
  EXPECT_EQ(scene.name, "cube");
  EXPECT_EQ(scene.units, "mm");
  EXPECT_DOUBLE_EQ(scene.metres_per_unit, 0.001);

  ASSERT_TRUE(single_elastic_object(scene).mesh.box.has_value());
  EXPECT_TRUE(single_elastic_object(scene).mesh.file.empty());
  const BoxMeshSpec& box = *single_elastic_object(scene).mesh.box;
  for (int a = 0; a < 3; ++a) {
    EXPECT_TRUE(near(box.size[a], 0.13)) << "axis " << a << ": " << box.size[a];
    EXPECT_EQ(box.divisions[a], 11);
  }
  EXPECT_TRUE(near(box.min_corner.x(), -0.065));
  EXPECT_TRUE(near(box.min_corner.y(), -0.065));
  EXPECT_TRUE(near(box.min_corner.z(), -0.13));

  EXPECT_DOUBLE_EQ(single_elastic_object(scene).material.youngs_modulus, 1.0e6);
  EXPECT_DOUBLE_EQ(single_elastic_object(scene).material.poisson_ratio, 0.4);

  ASSERT_EQ(single_elastic_object(scene).fixed.size(), 1u);
  const FixedRegion& fixed = single_elastic_object(scene).fixed[0];
  EXPECT_EQ(fixed.axes, kAllAxes);
  EXPECT_EQ(fixed.nodes.kind, NodeSelector::Kind::plane);
  EXPECT_TRUE(near(fixed.nodes.plane_point.z(), -0.13));
  EXPECT_TRUE(fixed.nodes.plane_normal.isApprox(Eigen::Vector3d::UnitZ(), 1e-15));
  EXPECT_EQ(fixed.nodes.where,
            testing::source_path("scenes/cube.yaml") + ":14: objects[0].fixed[0]");

  ASSERT_EQ(single_elastic_object(scene).touchable.size(), 1u);
  EXPECT_EQ(single_elastic_object(scene).touchable[0].kind, NodeSelector::Kind::plane);
  EXPECT_TRUE(near(single_elastic_object(scene).touchable[0].plane_point.z(), 0.0));
  EXPECT_TRUE(single_elastic_object(scene).compliance.precompute_touchable);
  EXPECT_TRUE(single_elastic_object(scene).compliance.disk_cache);

  ASSERT_EQ(scene.tools.size(), 1u);
  EXPECT_EQ(scene.tools[0].name, "A");
  EXPECT_EQ(scene.tools[0].shape, ToolShape::point);
  EXPECT_EQ(scene.tools[0].radius, 0.0);
  EXPECT_TRUE(scene.obstacles.empty());

  EXPECT_DOUBLE_EQ(scene.haptic.rate_hz, 1000);
  EXPECT_DOUBLE_EQ(scene.haptic.force_limit_n, 3.3);
  EXPECT_EQ(scene.haptic.contact_model, ContactModel::node_translation);
}

// Every scene and motion the project ships loads and builds; the tools of a scene and the
// motions written for it fit (the trade-off's motions press inside the touchable surface).
TEST(SceneModel, EveryShippedSceneAndMotionLoads) {
  for (const char* file :
       {"scenes/cube.yaml", "scenes/brain.yaml", "scenes/tradeoff/cube_two_users.yaml",
        "scenes/tradeoff/brain.yaml", "scenes/tradeoff/brain_fine.yaml",
        "scenes/tradeoff/brain_spheres.yaml", "scenes/block/two_spheres.yaml",
        "scenes/block/two_spheres_coarse.yaml"}) {
    const Model model = build_model(load_scene(testing::source_path(file)));
    const ElasticBody& body = single_elastic_body(model);
    EXPECT_GT(body.touchable_nodes.size(), 10u) << file;
  }
  const Model fine =
      build_model(load_scene(testing::source_path("scenes/tradeoff/brain_fine.yaml")));
  EXPECT_EQ(single_elastic_body(fine).mesh.node_count(), 9015);
  for (const char* file :
       {"scenes/brain/surgeon_a.yaml", "scenes/brain/surgeon_b.yaml",
        "scenes/studies/press_front.yaml", "scenes/tradeoff/cube_press_slide.yaml",
        "scenes/tradeoff/cube_press_hold.yaml", "scenes/tradeoff/brain_press_slide.yaml",
        "scenes/tradeoff/brain_press_hold.yaml", "scenes/tradeoff/brain_sphere_press_slide.yaml",
        "scenes/tradeoff/brain_sphere_press_hold.yaml"}) {
    const Trajectory motion = load_trajectory(testing::source_path(file));
    EXPECT_GT(motion.duration(), 1.0) << file;
  }
  EXPECT_DOUBLE_EQ(
      load_trajectory(testing::source_path("scenes/tradeoff/cube_press_slide.yaml")).duration(),
      3.0);
  EXPECT_DOUBLE_EQ(
      load_trajectory(testing::source_path("scenes/tradeoff/cube_press_hold.yaml")).duration(),
      3.0);
}

TEST(SceneModel, CubeModelFixedAndTouchableNodesAreTheTwoFaces) {
  const Model model = build_model(load_scene(testing::source_path("scenes/cube.yaml")));
  const ElasticBody& body = single_elastic_body(model);
  EXPECT_EQ(body.mesh.node_count(), 1728);
  EXPECT_EQ(body.mesh.tet_count(), 7986);
  ASSERT_EQ(body.dofs.node_count(), 1728);

  // By hand from the coordinates: the rear face z = -0.13 m and the front face z = 0.
  std::vector<int> rear, front;
  for (int n = 0; n < body.mesh.node_count(); ++n) {
    const double z = body.mesh.nodes(2, n);
    if (std::abs(z + 0.13) < 1e-9) rear.push_back(n);
    if (std::abs(z) < 1e-9) front.push_back(n);
  }
  ASSERT_EQ(rear.size(), 144u);
  ASSERT_EQ(front.size(), 144u);

  std::vector<int> fixed;
  for (int n = 0; n < body.dofs.node_count(); ++n) {
    const AxisMask mask = body.dofs.fixed_axes[n];
    EXPECT_TRUE(mask == 0 || mask == kAllAxes) << "node " << n << " mask " << int(mask);
    if (mask != 0) fixed.push_back(n);
  }
  EXPECT_EQ(fixed, rear);
  EXPECT_EQ(body.dofs.free_count(), 3 * (1728 - 144));
  EXPECT_EQ(body.touchable_nodes, front);

  // 11 x 11 cells, two triangles each, all on the front face, all facing +z.
  EXPECT_EQ(body.touchable_triangles.size(), 2u * 11 * 11);
  for (int t : body.touchable_triangles) {
    const Triangle& tri = body.surface.triangles[t];
    for (int v : tri) EXPECT_NEAR(body.mesh.nodes(2, v), 0.0, 1e-12) << "triangle " << t;
    const Eigen::Vector3d normal = triangle_normal(body.mesh, tri);
    EXPECT_LT((normal - Eigen::Vector3d::UnitZ()).norm(), 1e-12)
        << "triangle " << t << " normal " << normal.transpose();
  }
}

TEST(SceneErrors, MessagesNameFileLineKeyAndExpectation) {
  const std::string& base = kBaseScene;
  std::vector<BadScene> cases;

  {
    const auto text = replaced(base, "poisson_ratio: 0.3", "poisson_ratio: 0.5");
    cases.push_back({"poisson ratio 0.5",
                     text,
                     "poisson_ratio: 0.5",
                     {"objects[0].material.poisson_ratio", "(-1, 0.5)", "found '0.5'"}});
  }
  {
    const auto text =
        replaced(base, "poisson_ratio: 0.3", "poisson_ratio: 0.3\n      element: quadratic_tet");
    cases.push_back({"unknown element",
                     text,
                     "element: quadratic_tet",
                     {"objects[0].material.element", "linear_tet", "nodal_pressure_tet",
                      "found 'quadratic_tet'"}});
  }
  {
    const auto text = replaced(base, "youngs_modulus: 1000", "youngs_modulus: -3");
    cases.push_back({"negative modulus",
                     text,
                     "youngs_modulus: -3",
                     {"objects[0].material.youngs_modulus", "positive modulus", "found '-3'"}});
  }
  {
    const auto text = replaced(base, "youngs_modulus: 1000", "youngs_modulos: 1000");
    cases.push_back({"misspelt key",
                     text,
                     "youngs_modulos",
                     {"objects[0].material.youngs_modulos", "unknown key",
                      "model, poisson_ratio, youngs_modulus"}});
  }
  {
    const auto text =
        replaced(base,
                 "    material:\n      model: linear_elastic\n      youngs_modulus: 1000\n"
                 "      poisson_ratio: 0.3\n",
                 "");
    // Reported at the object that lacks it; its map starts on the "- name: block" line.
    cases.push_back({"missing material",
                     text,
                     "- name: block",
                     {"objects[0]", "missing required key 'material'"}});
  }
  {
    const auto text = replaced(base, "size: [10, 10, 10]", "size: [10, 10]");
    cases.push_back({"vector of two",
                     text,
                     "size: [10, 10]",
                     {"objects[0].mesh.box.size", "a list of 3 numbers", "found a list of 2"}});
  }
  {
    const auto text = replaced(base, "units: mm", "units: inch");
    cases.push_back({"units inch", text, "units: inch", {"units", "m | cm | mm", "found 'inch'"}});
  }
  {
    const auto text = replaced(base, "divisions: [2, 2, 2]", "divisions: [2, 0, 2]");
    cases.push_back(
        {"zero divisions",
         text,
         "divisions: [2, 0, 2]",
         {"objects[0].mesh.box.divisions[1]", "an integer from 1 to 400", "found '0'"}});
  }
  {
    const auto text = replaced(base, "  rate_hz: 1000", "  rate_hz: 1000: 2");
    cases.push_back({"YAML syntax error", text, "rate_hz: 1000: 2", {"YAML syntax error"}});
  }
  {
    // A second object, a copy of the first.
    const auto object_begin = base.find("  - name: block");
    const auto object_end = base.find("tools:");
    const std::string object = base.substr(object_begin, object_end - object_begin);
    const auto text = replaced(
        base, "tools:", replaced(object, "name: block", "name: block  # again") + "tools:");
    // The second object's name is the offender.
    cases.push_back({"two objects of one name",
                     text,
                     "name: block  # again",
                     {"objects[1].name", "an object name not used before", "found 'block'"}});
  }
  {
    const auto text = replaced(base, "  - name: block\n", "  - name: block\n    model: rubber\n");
    cases.push_back({"unknown body model",
                     text,
                     "model: rubber",
                     {"objects[0].model", "linear_elastic", "found 'rubber'"}});
  }
  {
    const auto text = replaced(base, "tools:\n  - name: A\n    shape: point\n", "tools: []\n");
    cases.push_back(
        {"no tools", text, "tools: []", {"tools", "at least one tool", "found a list of 0"}});
  }
  {
    // One tool more than a session holds (kMaxUsers, common/kinds/session_limits.h).
    std::string tools = "tools:\n";
    for (int user = 0; user <= kMaxUsers; ++user)
      tools += "  - {name: T" + std::to_string(user) + ", shape: point}\n";
    const auto text = replaced(base, "tools:\n  - name: A\n    shape: point\n", tools);
    cases.push_back(
        {"more tools than users",
         text,
         "- {name: T0,",
         {"tools", "at most 4 tools", "found a list of " + std::to_string(kMaxUsers + 1)}});
  }
  {
    const auto text =
        replaced(base, "    shape: point\n", "    shape: point\n  - name: A\n    shape: point\n");
    // The second tool's name is the duplicate: the item starts three lines below "tools:".
    const int second_line = line_of(text, "tools:") + 3;
    const auto message = parse_error(text);
    ASSERT_TRUE(message.has_value());
    EXPECT_EQ(message->rfind(kSceneFile + ":" + std::to_string(second_line) + ":", 0), 0u)
        << *message;
    EXPECT_NE(message->find("tools[1].name"), std::string::npos) << *message;
    EXPECT_NE(message->find("a tool name not used before"), std::string::npos) << *message;
    EXPECT_NE(message->find("found 'A'"), std::string::npos) << *message;
  }
  {
    const auto text = replaced(base, "    shape: point\n", "    shape: sphere\n");
    cases.push_back({"sphere without radius",
                     text,
                     "- name: A",
                     {"tools[0]", "missing required key 'radius'"}});
  }
  {
    const auto text = replaced(base, "    shape: point\n", "    shape: point\n    radius: 2\n");
    cases.push_back({"point with radius",
                     text,
                     "radius: 2",
                     {"tools[0].radius", "a point tool has no radius"}});
  }
  {
    const auto text = replaced(base, "    shape: point\n",
                               "    shape: probe\n    trocar: [0, 0, 50]\n    radius: 2\n");
    cases.push_back({"probe with radius",
                     text,
                     "radius: 2",
                     {"tools[0].radius", "a probe tool has no radius (use shape: sphere)"}});
  }
  {
    const auto text = replaced(base, "    shape: point\n",
                               "    shape: forceps\n    trocar: [0, 0, 50]\n    radius: 2\n");
    cases.push_back({"forceps with radius",
                     text,
                     "radius: 2",
                     {"tools[0].radius", "a forceps tool has no radius (use shape: sphere)"}});
  }
  {
    const auto text =
        replaced(replaced(base, "    shape: point\n", "    shape: probe\n    trocar: [0, 0, 50]\n"),
                 "  rate_hz: 1000\n", "  rate_hz: 1000\n  contact_model: sphere\n");
    cases.push_back({"sphere contact model with a probe",
                     text,
                     "contact_model: sphere",
                     {"haptic.contact_model",
                      "needs sphere tools, and tool 'A' is a probe (give it shape: sphere"}});
  }
  {
    // The default closing step (0.02 rad, 1.146 degrees) would close the jaws past their opening.
    const auto text = replaced(
        base, "    shape: point\n",
        "    shape: forceps\n    trocar: [0, 0, 50]\n    jaws:\n      open_angle_deg: 1\n");
    cases.push_back(
        {"forceps opening below the default closing step",
         text,
         "open_angle_deg: 1",
         {"tools[0].jaws.open_angle_deg",
          "open_angle_deg 1 is below the closing step (closing_step_deg, by default 1.146): give a "
          "closing_step_deg of at most 1"}});
  }
  {
    const auto text =
        replaced(base, "  rate_hz: 1000\n", "  rate_hz: 1000\n  min_sim_rate_hz: 0\n");
    cases.push_back(
        {"minimum simulation rate 0",
         text,
         "min_sim_rate_hz: 0",
         {"haptic.min_sim_rate_hz", "expected a rate above 0 and at most 100000 Hz", "found '0'"}});
  }
  {
    const auto text = replaced(
        base, "tools:",
        "obstacles:\n  - name: floor\n    plane: {point: [0, 0, -1], normal: [0, 0, 1]}\n"
        "  - name: floor  # again\n    plane: {point: [0, 0, 20], normal: [0, 0, -1]}\ntools:");
    cases.push_back({"two obstacles of one name",
                     text,
                     "name: floor  # again",
                     {"obstacles[1].name", "an obstacle name not used before", "found 'floor'"}});
  }
  {
    const auto text = replaced(base, "tools:",
                               "obstacles:\n  - name: floor\n    plane:\n      point: [0, 0, -1]\n"
                               "      normal: [0, 0, 0]\ntools:");
    cases.push_back(
        {"obstacle plane without a normal",
         text,
         "normal: [0, 0, 0]",
         {"obstacles[0].plane.normal", "a non-zero normal vector", "found a list of 3"}});
  }
  {
    const auto text = replaced(
        base,
        "    fixed:\n      - plane:\n          point: [0, 0, 0]\n          normal: [0, 0, 1]\n"
        "        axes: xyz\n",
        "    fixed: []\n");
    cases.push_back({"empty fixed list",
                     text,
                     "fixed: []",
                     {"objects[0].fixed", "at least one fixed region", "found a list of 0"}});
  }
  {
    const auto text =
        replaced(base, "        axes: xyz\n",
                 "        box: {min: [0, 0, 0], max: [1, 1, 1]}\n        axes: xyz\n");
    // The offender is the fixed region's map, which starts on its "- plane:" line.
    cases.push_back({"plane and box",
                     text,
                     "      - plane:\n          point: [0, 0, 0]",
                     {"objects[0].fixed[0]", "exactly one of surface, box, plane or nodes"}});
  }
  {
    const auto text = replaced(base,
                               "      box:\n        min: [0, 0, 0]\n        size: [10, 10, 10]\n"
                               "        divisions: [2, 2, 2]\n",
                               "      file: no_such_mesh.msh\n");
    cases.push_back({"missing mesh file",
                     text,
                     "file: no_such_mesh.msh",
                     {"objects[0].mesh.file", "/nonexistent-cohaptic-test/scenes/no_such_mesh.msh",
                      "does not exist"}});
  }

  {
    const auto text = replaced(base, "haptic:\n", "network:\n  max_participants: 2\nhaptic:\n");
    cases.push_back({"more participants than tools",
                     text,
                     "max_participants: 2",
                     {"network.max_participants", "an integer from 1 to the number of tools (1)",
                      "found '2'"}});
  }
  {
    const auto text = replaced(base, "haptic:\n", "network:\n  max_users: 1\nhaptic:\n");
    cases.push_back({"unknown network key",
                     text,
                     "max_users: 1",
                     {"network.max_users", "unknown key", "max_participants"}});
  }

  {
    // A list as a map key: a scene error, not a YAML library exception.
    const auto text =
        replaced(base, "      youngs_modulus: 1000\n", "      ? [youngs, modulus]\n      : 1000\n");
    cases.push_back({"list as a key",
                     text,
                     "? [youngs, modulus]",
                     {"objects[0].material", "a map whose keys are names", "found a list of 2"}});
  }

  {
    // A name the system refuses (too long): a scene error, not std::filesystem's error.
    const std::string long_name(5000, 'm');
    const auto text = replaced(base,
                               "      box:\n        min: [0, 0, 0]\n        size: [10, 10, 10]\n"
                               "        divisions: [2, 2, 2]\n",
                               "      file: " + long_name + ".msh\n");
    cases.push_back({"file name too long",
                     text,
                     "file: mmm",
                     {"objects[0].mesh.file", "cannot be examined: File name too long"}});
  }
  {
    const auto text = replaced(base,
                               "      box:\n        min: [0, 0, 0]\n        size: [10, 10, 10]\n"
                               "        divisions: [2, 2, 2]\n",
                               "      file: /tmp\n");
    cases.push_back({"directory as mesh",
                     text,
                     "file: /tmp",
                     {"objects[0].mesh.file", "mesh file /tmp is a directory"}});
  }

  for (const BadScene& bad : cases) expect_scene_error(bad);
}

TEST(SceneLoad, MaxParticipantsDefaultsToOnePerToolAndMayBeFewer) {
  const std::string two_tools =
      replaced(kBaseScene, "    shape: point\n", "    shape: point\n  - name: B\n");
  EXPECT_EQ(parse_scene(two_tools, kSceneFile).network.max_participants, 2);
  const std::string one_at_a_time =
      replaced(two_tools, "haptic:\n", "network: {max_participants: 1}\nhaptic:\n");
  EXPECT_EQ(parse_scene(one_at_a_time, kSceneFile).network.max_participants, 1);
}

TEST(SceneLoad, ForcepsClosingStepMayBeAsLargeAsTheOpenAngle) {
  const std::string forceps = replaced(kBaseScene, "    shape: point\n",
                                       "    shape: forceps\n    trocar: [0, 0, 50]\n    jaws: "
                                       "{open_angle_deg: 1, closing_step_deg: 1}\n");
  const InstrumentSpec given = *parse_scene(forceps, kSceneFile).tools.at(0).instrument;
  EXPECT_DOUBLE_EQ(given.closing_step, given.open_angle);
  // Two degrees open is more than the default step of 0.02 rad.
  const std::string defaulted =
      replaced(forceps, "{open_angle_deg: 1, closing_step_deg: 1}", "{open_angle_deg: 2}");
  const InstrumentSpec instrument = *parse_scene(defaulted, kSceneFile).tools.at(0).instrument;
  EXPECT_DOUBLE_EQ(instrument.closing_step, 0.02);
  EXPECT_DOUBLE_EQ(instrument.open_angle, 2 * M_PI / 180);
}

TEST(SceneModel, SeveralObjectsCompileIntoOneBodyEachInTheSceneOrder) {
  // A second block beside the first, twice as fine; `model:` written out on one, defaulted on the
  // other.
  const auto object_begin = kBaseScene.find("  - name: block");
  const std::string object =
      kBaseScene.substr(object_begin, kBaseScene.find("tools:") - object_begin);
  std::string second = replaced(object, "name: block", "name: twin\n    model: linear_elastic");
  second = replaced(second, "divisions: [2, 2, 2]", "divisions: [4, 4, 4]");
  const Scene scene = parse_scene(replaced(kBaseScene, "tools:", second + "tools:"), kSceneFile);
  ASSERT_EQ(scene.objects.size(), 2u);
  EXPECT_EQ(scene.objects[1].name, "twin");
  EXPECT_EQ(
      scene.objects[1].where,
      kSceneFile + ":" +
          std::to_string(line_of(replaced(kBaseScene, "tools:", second + "tools:"), "name: twin")) +
          ": objects[1]");
  const Model model = build_model(scene);
  ASSERT_EQ(model.bodies.size(), 2u);
  EXPECT_EQ(elastic_body(model, 0).mesh.node_count(), 27);
  EXPECT_EQ(elastic_body(model, 1).mesh.node_count(), 125);
  EXPECT_EQ(elastic_body(model, 1).name, "twin");
  // The one-object tools say why they refuse.
  try {
    single_elastic_body(model);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("has 2 objects"), std::string::npos) << e.what();
  }
  EXPECT_THROW(elastic_body(model, 2), Error);
}

TEST(SceneErrors, MissingSceneFileNamesIt) {
  const std::string file = "/nonexistent-cohaptic-test/missing.yaml";
  try {
    load_scene(file);
    FAIL() << "no SceneError";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
  }
}

TEST(SceneModel, PerAxisFixingMatchesMasksComputedFromCoordinates) {
  // Sliding (symmetry) boundaries on three planes: each removes one rigid mode family,
  // together they make K_ff positive definite.
  const std::string text = R"(units: m
objects:
  - name: block
    mesh:
      box: {min: [0, 0, 0], size: [1, 1, 1], divisions: [2, 2, 2]}
    material: {youngs_modulus: 1000, poisson_ratio: 0.3}
    fixed:
      - plane: {point: [0, 0, 0], normal: [0, 0, 1]}
        axes: z
      - plane: {point: [0, 0, 0], normal: [1, 0, 0]}
        axes: x
      - plane: {point: [0, 0, 0], normal: [0, 1, 0]}
        axes: y
tools:
  - {name: A}
)";
  const Model model = build_model(parse_scene(text, "per_axis.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  ASSERT_EQ(body.mesh.node_count(), 27);
  int fixed_dofs = 0;
  int x_and_z_only = 0;
  for (int n = 0; n < body.mesh.node_count(); ++n) {
    const Eigen::Vector3d x = body.mesh.nodes.col(n);
    int expected = 0;
    if (std::abs(x.x()) < 1e-12) expected |= 0b001;
    if (std::abs(x.y()) < 1e-12) expected |= 0b010;
    if (std::abs(x.z()) < 1e-12) expected |= 0b100;
    EXPECT_EQ(int(body.dofs.fixed_axes[n]), int(expected)) << "node at " << x.transpose();
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(body.dofs.is_fixed(n, a), ((expected >> a) & 1) != 0);
      fixed_dofs += (expected >> a) & 1;
      if (((expected >> a) & 1) == 0) {
        ASSERT_GE(body.dofs.free_index[3 * n + a], 0);
        EXPECT_EQ(body.dofs.free_dofs[body.dofs.free_index[3 * n + a]], 3 * n + a);
      } else {
        EXPECT_EQ(body.dofs.free_index[3 * n + a], -1);
      }
    }
    if (expected == 0b101) ++x_and_z_only;
  }
  EXPECT_EQ(x_and_z_only, 2);  // the line x = z = 0 without the origin: y = 0.5 and 1
  EXPECT_EQ(fixed_dofs, 3 * 9);
  EXPECT_EQ(body.dofs.free_count(), 3 * 27 - fixed_dofs);
}

std::string build_error(const std::string& text) {
  try {
    build_model(parse_scene(text, "selectors.yaml"));
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no SceneError)";
}

TEST(SceneModel, SelectorThatSelectsNothingNamesItsKeyPath) {
  const std::string outside =
      replaced(kBaseScene, "        axes: xyz\n",
               "        axes: xyz\n      - plane:\n          point: [0, 0, 50]\n"
               "          normal: [0, 0, 1]\n        axes: z\n");
  ASSERT_TRUE(parse_error(outside) == std::nullopt) << *parse_error(outside);
  const std::string message = build_error(outside);
  EXPECT_NE(message.find("objects[0].fixed[1]"), std::string::npos) << message;
  EXPECT_NE(message.find("selects no"), std::string::npos) << message;

  // The same through select_nodes directly, with a box selector that misses the mesh.
  const TetMesh mesh =
      make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), Eigen::Vector3i::Constant(2));
  const BoundarySurface surface = extract_boundary_surface(mesh);
  NodeSelector box;
  box.kind = NodeSelector::Kind::box;
  box.box_min = Eigen::Vector3d::Constant(2);
  box.box_max = Eigen::Vector3d::Constant(3);
  box.where = "objects[0].touchable[3]";
  try {
    select_nodes(box, mesh, surface, true);
    ADD_FAILURE() << "no SceneError";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("objects[0].touchable[3]"), std::string::npos) << e.what();
  }
  // A box around the top face selects exactly the 9 nodes with z = 1.
  box.box_min = Eigen::Vector3d(-1, -1, 0.9);
  box.box_max = Eigen::Vector3d(2, 2, 1.1);
  std::vector<int> top;
  for (int n = 0; n < mesh.node_count(); ++n)
    if (mesh.nodes(2, n) == 1.0) top.push_back(n);
  EXPECT_EQ(select_nodes(box, mesh, surface, true), top);
}

TEST(SceneModel, UnknownOrInteriorNodeIdIsNamed) {
  const std::string unknown = replaced(
      kBaseScene, "      - plane:\n          point: [0, 0, 0]\n          normal: [0, 0, 1]\n",
      "      - nodes: [1, 98765]\n");
  const std::string message = build_error(unknown);
  EXPECT_NE(message.find("objects[0].fixed[0]"), std::string::npos) << message;
  EXPECT_NE(message.find("98765"), std::string::npos) << message;

  // Node tags are index + 1; node index 13 is the centre of the 2x2x2 box, not on the surface.
  const std::string interior =
      replaced(kBaseScene, "          point: [0, 0, 10]\n          normal: [0, 0, 1]\n",
               "          point: [0, 0, 10]\n          normal: [0, 0, 1]\n      - nodes: [14]\n");
  const std::string interior_message = build_error(interior);
  EXPECT_NE(interior_message.find("objects[0].touchable[1]"), std::string::npos)
      << interior_message;
  EXPECT_NE(interior_message.find("node 14"), std::string::npos) << interior_message;
  EXPECT_NE(interior_message.find("not on the surface"), std::string::npos) << interior_message;
}

}  // namespace
}  // namespace cohaptic

namespace cohaptic {
namespace {

// A mass-spring object in block style, one value per line (the error tests below replace one).
const std::string kNoodleScene = R"(name: noodle_test
units: mm
objects:
  - name: noodle
    model: mass_spring
    tube:
      centre_line: [[0, 0, 5], [40, 0, 5]]
      radius: 5
      sections: 11
    material:
      youngs_modulus: 700
      density: 9049
      spring_damping: 1.0e-6
      node_damping: 0.007
    plane:
      point: [0, 0, 0]
      normal: [0, 0, 1]
      static_friction: 0.5
      dynamic_friction: 0.2
    tool_friction: 0.3
    heated:
      - box:
          min: [-1, -10, -10]
          max: [20, 10, 10]
        temperature_rise: 40
        expansion_coefficient: 1.0e-4
        coupling: 100
    ir:
      sections: 3
      rate_hz: 200
tools:
  - name: A
    shape: sphere
    radius: 2
)";

TEST(MassSpringScene, NoodleObjectParsesInSIUnitsAndCompiles) {
  const Scene scene = parse_scene(kNoodleScene, kSceneFile);
  const auto& spec = std::get<MassSpringObjectSpec>(scene.objects.at(0).body);
  EXPECT_EQ(spec.tube.sections, 11);
  EXPECT_TRUE(near(spec.tube.radius, 0.005));
  EXPECT_TRUE(near(spec.tube.centre_line[1].x(), 0.040));
  EXPECT_TRUE(near(spec.material.density, 9049));
  ASSERT_TRUE(spec.plane.has_value());
  EXPECT_DOUBLE_EQ(spec.plane->dynamic_friction, 0.2);
  ASSERT_EQ(spec.heated.size(), 1u);
  EXPECT_TRUE(near(spec.heated[0].box_max.x(), 0.020));
  EXPECT_EQ(spec.ir.sections, 3);
  EXPECT_DOUBLE_EQ(spec.ir.rate_hz, 200);

  const Model model = build_model(scene);
  const auto& body = std::get<MassSpringModel>(model.bodies.at(0));
  EXPECT_EQ(body.network.node_count(), 11 * kSectionNodes);
  EXPECT_GT(body.heated_springs, 50);
  EXPECT_LT(body.network.parameters.time_step, body.critical_time_step);
  EXPECT_EQ(body.section_of_node.back(), 10);
  try {
    elastic_body(model, 0);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is a mass_spring body"), std::string::npos) << e.what();
  }
}

TEST(MassSpringScene, ShippedNoodleScenesCompile) {
  for (const char* file : {"scenes/thin/noodle.yaml", "scenes/thin/noodle_light.yaml",
                           "scenes/thin/noodle_heated.yaml"}) {
    const Model model = build_model(load_scene(testing::source_path(file)));
    const auto& body = std::get<MassSpringModel>(model.bodies.at(0));
    EXPECT_EQ(body.network.node_count(), 360) << file;
    EXPECT_EQ(body.heated_springs > 0, std::string(file).find("heated") != std::string::npos)
        << file;
  }
}

TEST(MassSpringScene, ErrorsNameFileLineKeyAndExpectation) {
  const BadScene cases[] = {
      {"unknown model",
       replaced(kNoodleScene, "model: mass_spring", "model: mass_springs"),
       "model: mass_springs",
       {"objects[0].model", "linear_elastic", "mass_spring"}},
      {"unknown key",
       replaced(kNoodleScene, "tool_friction: 0.3", "tool_frictions: 0.3"),
       "tool_frictions",
       {"tool_frictions"}},
      {"no tube", replaced(kNoodleScene, "    tube:\n", "    tubes:\n"), "tubes:", {"tubes"}},
      {"both counts",
       replaced(kNoodleScene, "sections: 11", "sections: 11\n      section_spacing: 2"),
       "centre_line",
       {"objects[0].tube", "exactly one of sections or section_spacing"}},
      {"one point",
       replaced(kNoodleScene, "[[0, 0, 5], [40, 0, 5]]", "[[0, 0, 5]]"),
       "centre_line",
       {"objects[0].tube.centre_line", "at least 2 points"}},
      {"negative density",
       replaced(kNoodleScene, "density: 9049", "density: -1"),
       "density: -1",
       {"objects[0].material.density", "positive density"}},
      {"dynamic above static",
       replaced(kNoodleScene, "dynamic_friction: 0.2", "dynamic_friction: 0.7"),
       "dynamic_friction: 0.7",
       {"objects[0].plane.dynamic_friction", "up to the static"}},
      {"heating past zero stiffness",
       replaced(kNoodleScene, "temperature_rise: 40", "temperature_rise: 100"),
       "- box:",
       {"objects[0].heated[0]", "no stiffness"}},
      {"no sections sent",
       replaced(kNoodleScene, "sections: 3", "sections: 0"),
       "sections: 0",
       {"objects[0].ir.sections", "from 1"}},
  };
  for (const BadScene& bad : cases) expect_scene_error(bad);
}

// A direction of huge components (finite numbers) has a squared length that overflows, so
// normalize() would make it the zero vector: a plane without a normal, a tube ring without
// its orientation. It is scaled without overflow.
TEST(Scene, DirectionsOfHugeComponentsBecomeUnitVectors) {
  const Eigen::Vector3d diagonal = Eigen::Vector3d(1, 1, 0).normalized();
  const Scene solid = parse_scene(
      replaced(kBaseScene, "normal: [0, 0, 1]", "normal: [1.0e200, 1.0e200, 0]"), kSceneFile);
  EXPECT_TRUE(std::get<ElasticObjectSpec>(solid.objects.at(0).body)
                  .fixed.at(0)
                  .nodes.plane_normal.isApprox(diagonal));
  const Scene walled = parse_scene(replaced(kBaseScene, "tools:",
                                            "obstacles:\n  - name: wall\n    plane: {point: [0, 0, "
                                            "-1], normal: [1.0e200, 1.0e200, 0]}\ntools:"),
                                   kSceneFile);
  ASSERT_TRUE(walled.obstacles.at(0).plane.has_value());
  EXPECT_TRUE(walled.obstacles.at(0).plane->second.isApprox(diagonal))
      << walled.obstacles.at(0).plane->second.transpose();
  const Scene tube = parse_scene(
      replaced(replaced(kNoodleScene, "normal: [0, 0, 1]", "normal: [1.0e200, 1.0e200, 0]"),
               "radius: 5\n", "radius: 5\n      up: [0, 1.0e300, 1.0e300]\n"),
      kSceneFile);
  const auto& spec = std::get<MassSpringObjectSpec>(tube.objects.at(0).body);
  EXPECT_TRUE(spec.tube.up.isApprox(Eigen::Vector3d(0, 1, 1).normalized()));
  // Whose length is itself past the largest double.
  const Scene largest = parse_scene(
      replaced(kBaseScene, "normal: [0, 0, 1]", "normal: [1.7e308, 1.7e308, 0]"), kSceneFile);
  EXPECT_TRUE(std::get<ElasticObjectSpec>(largest.objects.at(0).body)
                  .fixed.at(0)
                  .nodes.plane_normal.isApprox(diagonal));
  ASSERT_TRUE(spec.plane.has_value());
  EXPECT_TRUE(spec.plane->normal.isApprox(diagonal));
}

// tube_network makes kSectionNodes nodes a section (NoodleObjectParsesInSIUnitsAndCompiles
// checks that count): the most sections a body's node limit allows are parsed, one more is
// refused, however the count is given. Parsed only: building the tube is not needed.
TEST(MassSpringScene, TubeOfMoreNodesThanABodyMayHaveIsRefused) {
  const int most = static_cast<int>(kMaxBodyNodes / kSectionNodes);
  const std::string limit = std::to_string(kMaxBodyNodes);
  const std::string under =
      replaced(kNoodleScene, "sections: 11", "sections: " + std::to_string(most));
  EXPECT_EQ(std::get<MassSpringObjectSpec>(parse_scene(under, kSceneFile).objects.at(0).body)
                .tube.sections,
            most);
  const std::string over =
      replaced(kNoodleScene, "sections: 11", "sections: " + std::to_string(most + 1));
  expect_scene_error(
      {"one section too many",
       over,
       "sections: " + std::to_string(most + 1),
       {"objects[0].tube.sections", "expected sections giving at most " + limit +
                                        " nodes (9 per section), not " +
                                        std::to_string(kSectionNodes * (most + 1)) + " (" +
                                        std::to_string(most + 1) + " sections)"}});

  // A centre line of L mm in 1 mm steps has L + 1 sections.
  const std::string spaced =
      replaced(kNoodleScene, "      sections: 11\n", "      section_spacing: 1\n");
  const std::string spaced_under =
      replaced(spaced, "[40, 0, 5]", "[" + std::to_string(most - 1) + ", 0, 5]");
  EXPECT_EQ(std::get<MassSpringObjectSpec>(parse_scene(spaced_under, kSceneFile).objects.at(0).body)
                .tube.sections,
            most);
  const std::string spaced_over =
      replaced(spaced, "[40, 0, 5]", "[" + std::to_string(most) + ", 0, 5]");
  expect_scene_error(
      {"a spacing giving one section too many",
       spaced_over,
       "section_spacing: 1",
       {"objects[0].tube.section_spacing",
        "expected a spacing giving at most " + limit + " nodes (9 per section), not " +
            std::to_string(kSectionNodes * (most + 1)) + " (" + std::to_string(most + 1) +
            " sections)",
        "found '1'"}});
}

TEST(MassSpringScene, TimeStepAboveTheCriticalOneIsRefusedNamingTheObject) {
  const Scene scene = parse_scene(
      replaced(kNoodleScene, "tool_friction: 0.3", "tool_friction: 0.3\n    time_step: 0.05"),
      kSceneFile);
  try {
    build_model(scene);
    FAIL() << "no error";
  } catch (const SceneError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(kSceneFile + ":4: objects[0]: time_step 0.05 s", 0), 0u) << message;
    EXPECT_NE(message.find("critical step"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace cohaptic

namespace cohaptic {
namespace {

// A separating-tissue object in block style, its instruments naming the two tools.
const std::string kLayersSceneOfSceneTests = R"(name: layers_test
units: mm
objects:
  - name: layers
    model: separation
    layers:
      size: [40, 40]
      flap_thickness: 4
      base_thickness: 10
      divisions: [20, 20]
      flap_layers: 2
      base_layers: 3
    instruments:
      - tool: fibre
        laser: true
      - laser: false
        tool: forceps
        contact: push
tools:
  - name: forceps
  - name: fibre
)";

TEST(SeparationSceneErrors, AnInstrumentNamesAToolOfTheSceneOnceAtItsToolKey) {
  const Scene scene = parse_scene(kLayersSceneOfSceneTests, kSceneFile);
  const auto& spec = std::get<SeparationObjectSpec>(scene.objects.at(0).body);
  ASSERT_EQ(spec.instruments.size(), 2u);
  EXPECT_EQ(spec.instruments[1].tool, "forceps");
  EXPECT_EQ(spec.instruments[0].settings.contact, ContactMode::grasp);
  EXPECT_EQ(spec.instruments[1].settings.contact, ContactMode::push);
  const BadScene cases[] = {
      // The item starts on its `laser:` line; the message names the line of `tool:`.
      {"unknown tool",
       replaced(kLayersSceneOfSceneTests, "tool: forceps", "tool: scalpel"),
       "tool: scalpel",
       {"objects[0].instruments[1].tool", "expected the name of a scene tool", "found 'scalpel'"}},
      {"a tool listed twice",
       replaced(kLayersSceneOfSceneTests, "tool: forceps", "tool: fibre  # again"),
       "tool: fibre  # again",
       {"objects[0].instruments[1].tool", "expected a tool not named by an earlier instrument",
        "found 'fibre'"}},
      {"a contact of no kind",
       replaced(kLayersSceneOfSceneTests, "contact: push", "contact: poke"),
       "contact: poke",
       {"objects[0].instruments[1].contact", "grasp | push", "found 'poke'"}},
  };
  for (const BadScene& bad : cases) expect_scene_error(bad);
}

// A separation body is either the generated layers or two meshes of the user's own, never
// both; the meshes' keys are checked where they stand.
TEST(SeparationSceneErrors, OwnMeshesComeInsteadOfTheLayersNotBesideThem) {
  // The lines from `key:` up to `instruments:`: the object's bodies.
  const auto bodies_of = [](const std::string& scene, const std::string& key) {
    const std::size_t from = scene.find("    " + key + ":");
    return scene.substr(from, scene.find("    instruments:") - from);
  };
  const std::string own_meshes =
      replaced(kLayersSceneOfSceneTests, bodies_of(kLayersSceneOfSceneTests, "layers"),
               R"(    pulled:
      mesh: {box: {min: [0, 0, 0], size: [40, 40, 4], divisions: [4, 4, 1]}}
      material: {youngs_modulus: 60000, poisson_ratio: 0.45}
      fixed: [{plane: {point: [40, 0, 0], normal: [1, 0, 0]}}]
    base:
      mesh: {box: {min: [0, 0, -10], size: [40, 40, 10], divisions: [4, 4, 1]}}
      material: {youngs_modulus: 60000, poisson_ratio: 0.45}
      fixed: [{plane: {point: [0, 0, -10], normal: [0, 0, 1]}}]
    interface: {sealed: [{plane: {point: [40, 0, 0], normal: [1, 0, 0]}}]}
)");
  const Scene scene = parse_scene(own_meshes, kSceneFile);
  const auto& spec = std::get<SeparationObjectSpec>(scene.objects.at(0).body);
  const auto& meshes = std::get<SeparationMeshesSpec>(spec.bodies);
  EXPECT_EQ(meshes.pulled.mesh.box->size, Eigen::Vector3d(0.04, 0.04, 0.004));
  EXPECT_EQ(meshes.base.fixed.at(0).nodes.plane_point.z(), -0.01);
  ASSERT_EQ(meshes.sealed.size(), 1u);
  EXPECT_EQ(meshes.sealed[0].plane_point.x(), 0.04);
  const BadScene cases[] = {
      {"layers beside own meshes",
       replaced(own_meshes, "    pulled:\n",
                "    layers: {size: [40, 40], flap_thickness: 4, "
                "base_thickness: 10, divisions: [4, 4]}\n    pulled:\n"),
       "      mesh: {box: {min: [0, 0, 0]",  // the map under `pulled:` starts here
       {"objects[0].pulled", "give either layers or pulled and base"}},
      {"neither layers nor meshes",
       replaced(own_meshes, bodies_of(own_meshes, "pulled"), ""),
       "  - name: layers",
       {"objects[0]", "expected layers (two generated boxes), or pulled and base"}},
      {"a base without supports",
       replaced(own_meshes, "      fixed: [{plane: {point: [0, 0, -10], normal: [0, 0, 1]}}]",
                "      fixed: []"),
       "      fixed: []",
       {"objects[0].base.fixed",
        "at least one fixed region (an unfixed body has no static solution)"}},
      {"a sealed region with axes",
       replaced(own_meshes, "normal: [1, 0, 0]}}]}", "normal: [1, 0, 0]}, axes: z}]}"),
       "    interface:",
       {"objects[0].interface.sealed[0]", "axes"}},
  };
  for (const BadScene& bad : cases) expect_scene_error(bad);
}

// make_two_layer_boxes meshes each layer as a box: (nx + 1)(ny + 1)(layers + 1) nodes, the
// two layers together the body's nodes. The most a body may have are parsed, more are refused.
// Parsed only: building them would fit the fields on a quarter of a million nodes.
TEST(SeparationSceneErrors, LayersOfMoreNodesThanABodyMayHaveAreRefused) {
  TwoLayerBoxes small;
  small.divisions = Eigen::Vector2i(3, 2);
  small.pulled_layers = 2;
  small.base_layers = 1;
  const SeparationBodies bodies = make_two_layer_boxes(small);
  EXPECT_EQ(bodies.pulled.mesh.node_count() + bodies.base.mesh.node_count(), 4 * 3 * (3 + 2));

  // 200 x (ny + 1) x (5 + 5) nodes: ny + 1 = kMaxBodyNodes / 2000 reaches the limit exactly.
  const int rows = static_cast<int>(kMaxBodyNodes / 2000);
  ASSERT_EQ(rows * 2000, kMaxBodyNodes);
  ASSERT_LE(rows, 200);
  const std::string four_and_four =
      replaced(replaced(kLayersSceneOfSceneTests, "flap_layers: 2", "flap_layers: 4"),
               "base_layers: 3", "base_layers: 4");
  const std::string at_limit = replaced(four_and_four, "divisions: [20, 20]",
                                        "divisions: [199, " + std::to_string(rows - 1) + "]");
  EXPECT_EQ(std::get<TwoLayerBoxes>(
                std::get<SeparationObjectSpec>(parse_scene(at_limit, kSceneFile).objects.at(0).body)
                    .bodies)
                .divisions.y(),
            rows - 1);
  const std::string over = replaced(four_and_four, "divisions: [20, 20]",
                                    "divisions: [199, " + std::to_string(rows) + "]");
  expect_scene_error(
      {"one row of cells too many",
       over,
       "divisions: [199,",
       {"objects[0].layers.divisions",
        "[199, " + std::to_string(rows) + "] with 4 flap and 4 base layers make " +
            std::to_string(200 * (rows + 1) * 10) + " nodes (200 x " + std::to_string(rows + 1) +
            " x (5 + 5)), more than the " + std::to_string(kMaxBodyNodes) + " a body may have"}});
}

}  // namespace
}  // namespace cohaptic
