// Separation bodies as scene files give them: on the user's own meshes (the interface found
// where the two meshes coincide, its rim sealed where the scene says) and several in one
// scene. Checked against: the generated layers built from the same geometry (the same
// supports, interface and fields), the paper's fracture law on a curved interface read from
// mesh files (F_n = J_c l_n held over BC, the hand's work J_c dLambda), and, with two bodies,
// each body tearing at its own J_c l_n while each user's client, evaluating the first IR it
// received, feels what the server computes.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>

#include "common/ir/evaluate_force.h"
#include "common/mesh/write_gmsh.h"
#include "common/model/model.h"
#include "common/scene/load_scene.h"
#include "common/separation/fracture_step.h"
#include "common/separation/pull_loop.h"
#include "common/separation/separation_setup.h"
#include "common/sim/scene_simulation.h"
#include "common/util/error.h"
#include "support/scratch_directory.h"
#include "support/wire_round_trip.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;

// The scene at `file`, its fields fitted here (not read from the user's cache).
Model model_without_cache(const std::filesystem::path& file) {
  Scene scene = load_scene(file);
  for (ObjectSpec& object : scene.objects)
    std::get<SeparationObjectSpec>(object.body).disk_cache = false;
  return build_model(scene);
}

const SeparationModel& separation_body(const Model& model, int index) {
  return std::get<SeparationModel>(model.bodies[static_cast<std::size_t>(index)]);
}

std::filesystem::path write_file(const std::filesystem::path& file, const std::string& text) {
  std::ofstream(file) << text;
  return file;
}

constexpr const char* kTools = R"(
tools:
  - {name: forceps}
)";

// 40 x 40 mm, 8 x 8 cells, a 4 mm flap of two cells on a 10 mm base of three: the layers
// generated, and the same boxes given as the user's meshes with the same supports and seal.
constexpr const char* kGeneratedLayers = R"(units: mm
objects:
  - name: layers
    model: separation
    layers: {size: [40, 40], flap_thickness: 4, base_thickness: 10, divisions: [8, 8]}
)";

constexpr const char* kLayersAsOwnMeshes = R"(units: mm
objects:
  - name: layers
    model: separation
    pulled:
      mesh: {box: {min: [0, 0, 0], size: [40, 40, 4], divisions: [8, 8, 2]}}
      material: {youngs_modulus: 60000, poisson_ratio: 0.45}
      fixed: [{box: {min: [40, 0, 1], max: [40, 40, 4]}}]
    base:
      mesh: {box: {min: [0, 0, -10], size: [40, 40, 10], divisions: [8, 8, 3]}}
      material: {youngs_modulus: 60000, poisson_ratio: 0.45}
      fixed: [{plane: {point: [0, 0, -10], normal: [0, 0, 1]}}]
    interface:
      sealed: [{plane: {point: [40, 0, 0], normal: [1, 0, 0]}}]
)";

TEST(SeparationOwnMeshes, BoxMeshesWithSelectedSupportsBuildWhatTheGeneratedLayersBuild) {
  const testing::ScratchDirectory scratch;
  const Model generated = model_without_cache(
      write_file(scratch.path / "generated.yaml", std::string(kGeneratedLayers) + kTools));
  const Model own = model_without_cache(
      write_file(scratch.path / "own.yaml", std::string(kLayersAsOwnMeshes) + kTools));
  const SeparationModel& expected = separation_body(generated, 0);
  const SeparationModel& got = separation_body(own, 0);

  // The scene's selectors hold what make_two_layer_boxes holds, node for node.
  EXPECT_EQ(got.bodies.pulled.fixed_axes, expected.bodies.pulled.fixed_axes);
  EXPECT_EQ(got.bodies.base.fixed_axes, expected.bodies.base.fixed_axes);
  // The same interface, its rim sealed at x = 40 mm only (3 of the 4 sides stay open).
  EXPECT_EQ(got.interface.positions, expected.interface.positions);
  EXPECT_EQ(got.interface.triangles, expected.interface.triangles);
  EXPECT_EQ(got.interface.open_rim, expected.interface.open_rim);
  int open = 0;
  for (std::uint8_t bits : got.interface.open_rim) open += std::popcount(bits);
  EXPECT_EQ(open, 3 * 8);
  // And the same fields.
  const std::vector<double>& a = got.patch->fields;
  const std::vector<double>& b = expected.patch->fields;
  ASSERT_EQ(a.size(), b.size());
  double largest = 0, difference = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    largest = std::max(largest, std::abs(b[i]));
    difference = std::max(difference, std::abs(a[i] - b[i]));
  }
  EXPECT_LE(difference, 1e-12 * largest);
}

// The default layers' boxes, 30 x 30 mm in 12 x 12 cells, bent into a dome: the flap lifted
// by h(x, y) = 3 mm sin(pi x / a) sin(pi y / b), the base by h (1 + z / 10 mm) so that its
// bottom stays flat. Written in mm to two .msh files.
void write_domed_layers(const std::filesystem::path& dir) {
  TwoLayerBoxes boxes;
  boxes.size = Eigen::Vector2d(0.03, 0.03);
  boxes.divisions = Eigen::Vector2i(12, 12);
  SeparationBodies bodies = make_two_layer_boxes(boxes);
  const auto dome = [&](Eigen::Matrix3Xd& nodes) {
    for (Eigen::Index n = 0; n < nodes.cols(); ++n) {
      const double x = nodes(0, n), y = nodes(1, n), z = nodes(2, n);
      const double h = 0.003 * std::sin(std::numbers::pi * x / boxes.size.x()) *
                       std::sin(std::numbers::pi * y / boxes.size.y());
      nodes(2, n) = z + (z >= 0 ? h : h * (1 + z / boxes.base_thickness));
    }
    nodes *= 1e3;  // the files are in mm
  };
  dome(bodies.pulled.mesh.nodes);
  dome(bodies.base.mesh.nodes);
  write_gmsh41(dir / "flap.msh", bodies.pulled.mesh);
  write_gmsh41(dir / "bed.msh", bodies.base.mesh);
}

constexpr const char* kDomedLayers = R"(units: mm
objects:
  - name: dome
    model: separation
    pulled:
      mesh: {file: flap.msh}
      material: {youngs_modulus: 60000, poisson_ratio: 0.45}
      fixed: [{box: {min: [30, 0, 0.5], max: [30, 30, 4]}}]
    base:
      mesh: {file: bed.msh}
      material: {youngs_modulus: 60000, poisson_ratio: 0.45}
      fixed: [{plane: {point: [0, 0, -10], normal: [0, 0, 1]}}]
    interface:
      sealed: [{plane: {point: [30, 0, 0], normal: [1, 0, 0]}}]
    fracture: {normal_length: 16}
)";

TEST(SeparationOwnMeshes, ACurvedInterfaceFromMeshFilesTearsAtJcLnAndTheHandPaysJcPerArea) {
  const testing::ScratchDirectory scratch;
  write_domed_layers(scratch.path);
  const Model model = model_without_cache(
      write_file(scratch.path / "dome.yaml", std::string(kDomedLayers) + kTools));
  const SeparationPatch& patch = *separation_body(model, 0).patch;
  ASSERT_EQ(patch.node_count(), 13 * 13);
  ASSERT_EQ(patch.triangle_count(), 2 * 12 * 12);
  // Read in mm, held in m; the dome's top is 3 mm up; every triangle faces the flap (up).
  EXPECT_NEAR(patch.positions.row(0).maxCoeff(), 0.03, 1e-12);
  EXPECT_NEAR(patch.positions.row(2).maxCoeff(), 0.003, 1e-12);
  for (int t = 0; t < patch.triangle_count(); ++t)
    EXPECT_GT(patch.normals[static_cast<std::size_t>(t)].z(), 0.5) << "triangle " << t;
  EXPECT_GT(patch.interface_area, 0.03 * 0.03);

  // Fig. 10 at the free rim x = 0, y = 15 mm, along the node's tilted normal.
  const int node = nearest_patch_node(patch, Vector3d(0, 0.015, 0));
  ASSERT_LT(holding_normal_length(patch, node), patch.normal_length);
  PullLoopSettings settings;
  settings.node = node;
  const PullLoop loop = run_pull_loop(patch, make_separation_state(patch), settings);
  // The node's normal leans off its first triangle's a little: l is between l_t and l_n.
  const double f_n = loop.threshold;
  EXPECT_NEAR(f_n, patch.toughness * patch.normal_length, 0.01 * f_n);
  int held = 0;
  double low = INFINITY, high = -INFINITY;
  for (const PullLoopSample& s : loop.samples)
    if (s.phase == PullPhase::fracture) {
      ++held;
      low = std::min(low, s.force);
      high = std::max(high, s.force);
      EXPECT_NEAR(s.force, f_n, 0.02 * f_n) << "at " << s.travel * 1e3 << " mm";
    }
  EXPECT_GT(held, 100);
  EXPECT_GT(loop.fracture_area, 1e-5);
  EXPECT_NEAR(loop.fracture_work, patch.toughness * loop.fracture_area,
              0.01 * patch.toughness * loop.fracture_area);
  EXPECT_GT(loop.net_work, 0);  // passive
  std::printf(
      "  dome: BC %d samples at %.4f..%.4f N (J_c l %.4f N), %.2f mm^2 separated, "
      "work %.4e J against J_c dLambda %.4e J\n",
      held, low, high, f_n, loop.fracture_area * 1e6, loop.fracture_work,
      patch.toughness * loop.fracture_area);
}

// scenes/separation/flap_on_bed.yaml: a 30 x 24 mm flap on a wider bed. The interface is
// the flap's footprint only, sealed on its held end; a pull at its free rim x = 4 mm holds
// J_c l_n while the crack grows, and the hand pays J_c per area.
TEST(SeparationOwnMeshes, TheFlapOnABedSceneTearsItsFreeRimAtJcLn) {
  const Model model =
      model_without_cache(std::string(COHAPTIC_SOURCE_DIR) + "/scenes/separation/flap_on_bed.yaml");
  const SeparationModel& body = separation_body(model, 0);
  const SeparationPatch& patch = *body.patch;
  EXPECT_EQ(patch.node_count(), 16 * 13);
  EXPECT_EQ(patch.triangle_count(), 2 * 15 * 12);
  EXPECT_NEAR(patch.interface_area, 0.030 * 0.024, 1e-15);
  EXPECT_NEAR(patch.positions.row(0).minCoeff(), 0.004, 1e-15);
  EXPECT_NEAR(patch.positions.row(0).maxCoeff(), 0.034, 1e-15);
  int open = 0;
  for (std::uint8_t bits : body.interface.open_rim) open += std::popcount(bits);
  EXPECT_EQ(open, 2 * (15 + 12) - 12);  // all but the 12 edges of the held end
  EXPECT_EQ(body.plateau.held, body.plateau.nodes);

  PullLoopSettings settings;
  settings.node = nearest_patch_node(patch, Vector3d(0.004, 0.020, 0));
  const PullLoop loop = run_pull_loop(patch, make_separation_state(patch), settings);
  const double f_n = patch.toughness * patch.normal_length;
  ASSERT_DOUBLE_EQ(loop.threshold, f_n);
  int held = 0;
  for (const PullLoopSample& s : loop.samples)
    if (s.phase == PullPhase::fracture) {
      ++held;
      EXPECT_NEAR(s.force, f_n, 0.02 * f_n) << "at " << s.travel * 1e3 << " mm";
    }
  EXPECT_GT(held, 100);
  EXPECT_NEAR(loop.fracture_work, patch.toughness * loop.fracture_area,
              0.01 * patch.toughness * loop.fracture_area);
}

TEST(SeparationOwnMeshes, MeshesThatDoNotTouchAreRefusedNamingTheObject) {
  const testing::ScratchDirectory scratch;
  std::string text = std::string(kLayersAsOwnMeshes) + kTools;
  text.replace(text.find("min: [0, 0, 0], size: [40, 40, 4]"), 33,
               "min: [0, 0, 1], size: [40, 40, 4]");
  text.replace(text.find("min: [40, 0, 1], max: [40, 40, 4]"), 33,
               "min: [40, 0, 2], max: [40, 40, 5]");
  const std::filesystem::path file = write_file(scratch.path / "apart.yaml", text);
  try {
    model_without_cache(file);
    ADD_FAILURE() << "built a separation body whose meshes share no surface";
  } catch (const SceneError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("apart.yaml:3: objects[0]"), std::string::npos) << message;
    EXPECT_NE(message.find("share no boundary triangle"), std::string::npos) << message;
  }
}

// scenes/separation/two_flaps.yaml: a left body (J_c = 75 J/m^2) and a right one 50 mm
// over (120 J/m^2). Each user's forceps close on its body's free rim and pull it up 12 mm
// at 10 mm/s; each client evaluates the first IR it received, over the wire, on every tick.
TEST(SeparationScenes, TwoBodiesTearEachAtItsOwnJcLnAndEachClientFeelsItsOwn) {
  const Model model =
      model_without_cache(std::string(COHAPTIC_SOURCE_DIR) + "/scenes/separation/two_flaps.yaml");
  ASSERT_EQ(model.bodies.size(), 2u);
  std::vector<ComplianceColumns*> columns(model.bodies.size(), nullptr);
  SceneSimulation scene(model, columns, model.scene.tools, SimulationOptions{});
  const double dt = 1e-3;
  const Vector3d rims[2] = {Vector3d(0, 0.015, 0.0002), Vector3d(0.05, 0.015, 0.0002)};
  const auto tip = [&](int user, int tick) -> Vector3d {
    return rims[user] + Vector3d(0, 0, std::clamp((tick - 10) * 1e-5, 0.0, 0.012));
  };
  const auto jaws = [](int tick) { return tick >= 5 ? 1u : 0u; };
  for (int u = 0; u < 2; ++u) scene.set_tool(u, tip(u, 0), jaws(0));
  scene.step(0);
  std::vector<PreparedIR> client_irs;
  std::vector<EvaluationState> clients;
  for (int u = 0; u < 2; ++u) {
    ASSERT_EQ(scene.body_of(u), u);
    ASSERT_TRUE(scene.ir(u));
    client_irs.push_back(prepare_ir(testing::over_the_wire(scene.ir(u)->ir)));
  }
  for (const PreparedIR& ir : client_irs) clients.push_back(make_evaluation_state(ir));

  double peak[2] = {0, 0}, largest_difference[2] = {0, 0};
  StepReport report;
  for (int i = 1; i <= 1300; ++i) {
    for (int u = 0; u < 2; ++u) scene.set_tool(u, tip(u, i), jaws(i));
    report = scene.step(i * dt);
    for (int u = 0; u < 2; ++u) {
      const ForceSample server = scene.force(u);
      const ForceSample client =
          evaluate_force(client_irs[static_cast<std::size_t>(u)],
                         clients[static_cast<std::size_t>(u)], tip(u, i), {}, dt, jaws(i));
      largest_difference[u] = std::max(largest_difference[u], (client.force - server.force).norm());
      peak[u] = std::max(peak[u], -server.force.z());
    }
  }
  double fractured = 0;
  for (int u = 0; u < 2; ++u) {
    const SeparationModel& body = separation_body(model, u);
    const auto& layers = std::get<SeparationSimulation>(scene.body(u));
    const double f_n = body.patch->normal_threshold;
    EXPECT_DOUBLE_EQ(f_n, body.spec.settings.fracture.toughness * 0.012);
    EXPECT_NEAR(peak[u], f_n, 0.05 * f_n) << body.name;
    EXPECT_GT(layers.fractured_area(), 1e-5) << body.name;
    EXPECT_LE(largest_difference[u], 1e-9 * peak[u]) << body.name;
    // Each body tore where its own user pulled: at its rim x = origin.x, nowhere else.
    for (int t = 0; t < body.patch->triangle_count(); ++t) {
      if (layers.state().separated[static_cast<std::size_t>(t)] > 0) {
        EXPECT_LT(body.patch->centroids[static_cast<std::size_t>(t)].x() - u * 0.05, 0.015)
            << body.name << " triangle " << t;
      }
    }
    fractured += layers.fractured_area();
    std::printf("  %s: peak %.4f N against J_c l_n %.4f N, %.2f mm^2 torn\n", body.name.c_str(),
                peak[u], f_n, layers.fractured_area() * 1e6);
  }
  EXPECT_NEAR(report.fractured_m2, fractured, 1e-18);
}

}  // namespace
}  // namespace cohaptic
