// The separating-tissue body in scenes: `model: separation` loads with
// its cited settings, compiles into a Model (the fields fitted to our FEM) and is stepped
// by the server's scene simulation: two users on one interface, the server deciding fracture and
// vaporisation, each user's IR rebuilt when the separated state changes, its epochs rising.
// Checked against: the scene file's settings and the paper's laws (Eq. 20's v_s, the
// groove's area l_f L, F_n = J_c l_n held while the flap tears), and the IRs' own states.
#include <gtest/gtest.h>

#include <fstream>
#include <set>

#include "common/model/model.h"
#include "common/scene/load_scene.h"
#include "common/sim/scene_simulation.h"
#include "proto/wire/surface_mesh_message.h"
#include "support/run_program.h"
#include "support/scratch_directory.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;

const Model& two_layers_model() {
  static const Model model = [] {
    Scene scene =
        load_scene(std::string(COHAPTIC_SOURCE_DIR) + "/scenes/separation/two_layers.yaml");
    std::get<SeparationObjectSpec>(scene.objects[0].body).disk_cache =
        false;  // the test fits the fields itself
    return build_model(scene);
  }();
  return model;
}

TEST(SeparationScene, TheTwoLayerSceneLoadsWithItsCitedSettings) {
  const Model& model = two_layers_model();
  const auto& body = std::get<SeparationModel>(model.bodies[0]);
  const SeparationPatch& patch = *body.patch;
  EXPECT_EQ(patch.node_count(), 21 * 21);
  EXPECT_EQ(patch.triangle_count(), 2 * 20 * 20);
  EXPECT_NEAR(patch.interface_area, 0.04 * 0.04, 1e-15);
  EXPECT_EQ(patch.degree, 3);
  EXPECT_DOUBLE_EQ(patch.normal_threshold, 75 * 0.012);
  EXPECT_DOUBLE_EQ(patch.tangential_threshold, 75 * 0.006);
  // v_s = alpha P / (q l_f^2), q = rho (c_p dT + H) for water (Eqs. 19-20): 52 mm/s.
  const double q = 1000 * (4180 * 63 + 2.26e6);
  EXPECT_NEAR(patch.vaporisation_speed, 0.5 * 80 / (q * 0.55e-3 * 0.55e-3), 1e-12);
  EXPECT_NEAR(patch.vaporisation_speed, 0.052, 0.001);
  EXPECT_LE(patch.force_limit, model.scene.haptic.force_limit_n);
  // A client's Welcome shows the interface (vertex i = interface node i).
  const wire::SurfaceMesh surface = wire::surface_mesh_message(model.bodies[0]);
  EXPECT_EQ(surface.vertices_size(), 3 * patch.node_count());
  EXPECT_EQ(surface.triangles_size(), 3 * patch.triangle_count());
  ASSERT_EQ(body.spec.instruments.size(), 1u);
  EXPECT_EQ(body.spec.instruments[0].tool, "fibre");
  EXPECT_TRUE(body.spec.instruments[0].settings.laser);
}

TEST(SeparationScene, AnInstrumentOfAnUnknownToolIsRefusedWithItsLine) {
  const testing::ScratchDirectory scratch;
  const std::filesystem::path& dir = scratch.path;
  std::ifstream in(std::string(COHAPTIC_SOURCE_DIR) + "/scenes/separation/two_layers.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("{tool: fibre, laser: true}"), 26, "{tool: scalpel, laser: true}");
  std::ofstream(dir / "bad.yaml") << text;
  try {
    load_scene(dir / "bad.yaml");
    ADD_FAILURE() << "accepted an instrument of no scene tool";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("found 'scalpel'"), std::string::npos) << e.what();
  }
}

// The scene's two users on the server's simulation, 1 ms steps: the forceps grasp the free
// rim and pull it up; the fibre cuts a groove across the middle, then grasps before it and
// pushes into it.
TEST(SeparationScene, TwoUsersTearAndCutOneInterfaceAndTheirIrsFollow) {
  const Model& model = two_layers_model();
  const auto& body = std::get<SeparationModel>(model.bodies[0]);
  std::vector<ComplianceColumns*> columns(model.bodies.size(), nullptr);
  SceneSimulation scene(model, columns, model.scene.tools, SimulationOptions{});
  const auto& layers = std::get<SeparationSimulation>(scene.body(0));
  const SeparationPatch& patch = *body.patch;
  const double dt = 1e-3;
  const Vector3d rim(0, 0.02, 0.0002), from(0.0205, 0.012, 0.0002), to(0.0205, 0.028, 0.0002),
      grip(0.02, 0.02, 0.0002);
  const double groove_speed = 0.02;
  const int cut = static_cast<int>(std::round((to - from).norm() / (groove_speed * dt)));
  std::uint64_t last_epoch[2] = {0, 0};
  int irs[2] = {0, 0};
  double peak_pull = 0, area_after_cut = 0, vaporised_after_cut = 0;
  for (int i = 0; i <= cut + 1400; ++i) {
    // Forceps: jaws close at 100 ms, pull up 8 mm at 10 mm/s from 200 ms, then hold.
    const double up = std::clamp((i - 200) * 1e-5, 0.0, 0.008);
    scene.set_tool(0, rim + Vector3d(0, 0, up), i >= 100 ? 1u : 0u);
    // Fibre: the groove at 20 mm/s (laser, button 0), then to the grip, jaws (button 1), push +x.
    Vector3d tip;
    std::uint32_t buttons = 0;
    if (i <= cut) {
      tip = from + (to - from) * (double(i) / cut);
      buttons = 1;
    } else if (i <= cut + 100) {
      tip = to + (grip - to) * ((i - cut) / 100.0);
    } else {
      tip = grip + Vector3d(std::clamp((i - cut - 200) * 5e-6, 0.0, 0.005), 0, 0);
      buttons = i >= cut + 150 ? 2u : 0u;
    }
    scene.set_tool(1, tip, buttons);
    scene.step(i * dt);
    if (i == cut) {
      area_after_cut = layers.state().separated_area;
      vaporised_after_cut = layers.vaporised_area();
    }
    peak_pull = std::max(peak_pull, -scene.force(0).force.z());
    for (int u = 0; u < 2; ++u) {
      if (!scene.ir_changed(u)) continue;
      const auto& ir = scene.ir(u)->ir;
      EXPECT_GT(ir.epoch, last_epoch[u]);
      last_epoch[u] = ir.epoch;
      ++irs[u];
      // Each IR carries the server's separated state as it stood at that step.
      EXPECT_EQ(std::get<SeparationIr>(ir.body).state.separated_area,
                layers.state().separated_area);
      EXPECT_EQ(std::get<SeparationIr>(ir.body).tool.laser, u == 1);
    }
  }
  // The groove: l_f wide along its length (flat ends), below v_s (Eqs. 15-17).
  EXPECT_NEAR(vaporised_after_cut, patch.spot_diameter * (to - from).norm(),
              0.02 * patch.spot_diameter * (to - from).norm());
  EXPECT_GT(area_after_cut, 0);
  // The pull tore the flap at its free rim at F_n (the force held near the threshold).
  double rim_area = 0;
  for (int t = 0; t < patch.triangle_count(); ++t)
    if (patch.centroids[static_cast<std::size_t>(t)].x() < 0.006)
      rim_area += layers.state().separated[static_cast<std::size_t>(t)] *
                  patch.areas[static_cast<std::size_t>(t)];
  EXPECT_GT(rim_area, 1e-6);
  EXPECT_GT(layers.fractured_area(), rim_area);
  EXPECT_NEAR(peak_pull, patch.normal_threshold, 0.05 * patch.normal_threshold);
  // The push opened the groove: more separated than the groove and the pull's tear.
  EXPECT_GT(layers.state().separated_area, area_after_cut + 1e-6);
  // IRs followed the state at most at the body's IR rate.
  const double seconds = (cut + 1400) * dt;
  for (int u = 0; u < 2; ++u) {
    EXPECT_GT(irs[u], 5) << "user " << u;
    EXPECT_LE(irs[u], seconds * body.spec.ir_rate_hz + 2) << "user " << u;
  }
  RecordProperty("separated_area_mm2", std::to_string(layers.state().separated_area * 1e6));
}

// `cohaptic-lab separation-pull` draws Fig. 10 on the scene: the three phases in its
// samples, BC held at J_c l_n = 0.9 N, the work in BC equal to J_c times the area.
TEST(SeparationScene, TheFig10CommandWritesTheThreePhases) {
  const testing::ScratchDirectory scratch;
  const testing::ProgramRun run = testing::run_program(
      COHAPTIC_LAB_EXE, "--log-level warn separation-pull --no-disk-cache --scene " +
                            std::string(COHAPTIC_SOURCE_DIR) +
                            "/scenes/separation/two_layers.yaml --out " + scratch.path.string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("threshold J_c l = 0.9000 N"), std::string::npos) << run.out;
  EXPECT_TRUE(std::filesystem::exists(scratch.path / "fig10_force.svg"));
  EXPECT_TRUE(std::filesystem::exists(scratch.path / "fig10_area.svg"));
  std::ifstream csv(scratch.path / "pull_loop.csv");
  std::string line;
  std::getline(csv, line);
  std::set<char> phases;
  double largest = 0;
  while (std::getline(csv, line)) {
    phases.insert(line.back());
    largest = std::max(largest, std::stod(line.substr(line.find(',', line.find(',') + 1) + 1)));
  }
  EXPECT_EQ(phases, (std::set<char>{'A', 'B', 'C'}));
  EXPECT_NEAR(largest, 0.9, 0.02 * 0.9);
}

}  // namespace
}  // namespace cohaptic
