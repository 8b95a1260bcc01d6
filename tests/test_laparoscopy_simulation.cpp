// The laparoscopy tissue as a scene body (`model: home_spring`) with instrument tools, and
// the server's simulation of it:
//   - the scene keys load in SI units, and every mistake is named by file:line: key;
//   - a probe's P0 force (the client's evaluation of the IR the server built) equals Eq. 8
//     written out here on the whole surface, at the vertex nearest where a brute-force scan
//     of every triangle finds the shaft crossing (random pokes);
//   - forceps close while button 0 is held, grasp, feel the pull back along Eq. 8 while the
//     grasp point holds, and let go on button up (a new IR without the grasp, zero force);
//   - the display dents the surface: the grasp point follows the pull, nothing beyond R moves;
//   - in a SceneSimulation, each user gets its own instrument's IR.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>

#include "common/contact/segment_triangle_crossing.h"
#include "common/model/model.h"
#include "common/scene/load_scene.h"
#include "common/sim/home_spring_simulation.h"
#include "common/sim/scene_simulation.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;

// A 80 x 80 mm sheet at z = 0 in 4 mm cells; a probe from the left, forceps from the right.
const std::string kTissueScene = R"(name: tissue-test
units: mm
objects:
  - name: tissue
    model: home_spring
    surface: {grid: {min: [-40, -40, 0], size: [80, 80], divisions: [20, 20]}}
    stiffness: {home: 100, neighbour: 40}
    patch_radius: 12
    display: {deformation: polynomial, radius: 20}
tools:
  - {name: probe, shape: probe, trocar: [-60, 0, 120]}
  - {name: grasper, shape: forceps, trocar: [60, 0, 120], jaws: {length: 10, open_angle_deg: 40, closing_step_deg: 2, opening: [0, 1, 0]}}
haptic: {rate_hz: 1000, force_limit: 100}
)";

Scene tissue_scene(const std::string& text = kTissueScene) {
  return parse_scene(text, "tissue.yaml");
}

// Eq. 8 written out on the whole surface: the load holding `vertex` displaced by u, its
// 1-ring taken from the triangles' edges here.
Vector3d eq8_load(const HomeSpringBody& body, int vertex, const Vector3d& u) {
  std::set<int> ring;
  for (const Triangle& tri : body.surface.triangles)
    for (int k = 0; k < 3; ++k)
      if (tri[k] == vertex) {
        ring.insert(tri[(k + 1) % 3]);
        ring.insert(tri[(k + 2) % 3]);
      }
  const Vector3d rest = body.surface.vertices.col(vertex);
  Vector3d load = body.spec.home_stiffness * u;
  for (const int j : ring) {
    const Vector3d neighbour = body.surface.vertices.col(j);
    const Vector3d l = rest + u - neighbour;
    load += body.spec.neighbour_stiffness * (l.norm() - (rest - neighbour).norm()) * l / l.norm();
  }
  return load;
}

struct BruteCrossing {
  int vertex = -1;
  Vector3d point = Vector3d::Zero();
};

// The first crossing of pivot -> tool over every triangle, and its triangle's nearest corner.
BruteCrossing brute_force_crossing(const HomeSpringBody& body, const Vector3d& pivot,
                                   const Vector3d& tool) {
  BruteCrossing best;
  double best_t = 2;
  for (const Triangle& tri : body.surface.triangles) {
    const auto hit = segment_triangle_crossing(pivot, tool, body.surface.vertices.col(tri[0]),
                                               body.surface.vertices.col(tri[1]),
                                               body.surface.vertices.col(tri[2]));
    if (!hit || hit->t >= best_t) continue;
    best_t = hit->t;
    best.point = pivot + hit->t * (tool - pivot);
    best.vertex = tri[0];
    for (const int v : tri)
      if ((body.surface.vertices.col(v) - best.point).norm() <
          (body.surface.vertices.col(best.vertex) - best.point).norm())
        best.vertex = v;
  }
  return best;
}

std::string load_error(const std::string& text) {
  try {
    tissue_scene(text);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(loaded)";
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  if (at == std::string::npos) throw std::invalid_argument("no '" + from + "' in the scene");
  return text.replace(at, from.size(), to);
}

TEST(LaparoscopyScene, LoadsTheTissueAndTheInstrumentsInSiUnits) {
  const Scene scene = tissue_scene();
  const auto& spec = std::get<HomeSpringObjectSpec>(scene.objects[0].body);
  ASSERT_TRUE(spec.grid.has_value());
  EXPECT_EQ(spec.grid->min, Vector3d(-0.04, -0.04, 0));
  EXPECT_EQ(spec.grid->divisions, Eigen::Vector2i(20, 20));
  EXPECT_EQ(spec.home_stiffness, 100);
  EXPECT_EQ(spec.neighbour_stiffness, 40);
  EXPECT_DOUBLE_EQ(spec.patch_radius, 0.012);
  EXPECT_DOUBLE_EQ(spec.display_radius, 0.02);
  EXPECT_EQ(scene.tools[0].shape, ToolShape::probe);
  EXPECT_EQ(scene.tools[1].shape, ToolShape::forceps);
  ASSERT_TRUE(scene.tools[1].instrument.has_value());
  EXPECT_EQ(scene.tools[1].instrument->trocar, Vector3d(0.06, 0, 0.12));
  EXPECT_DOUBLE_EQ(scene.tools[1].instrument->jaw_length, 0.01);
  EXPECT_DOUBLE_EQ(scene.tools[1].instrument->open_angle, 40 * M_PI / 180);
  EXPECT_DOUBLE_EQ(scene.tools[1].instrument->closing_step, 2 * M_PI / 180);
  EXPECT_EQ(scene.tools[1].instrument->opening, Vector3d::UnitY());

  const Model model = build_model(scene);
  const auto& body = std::get<HomeSpringBody>(model.bodies[0]);
  EXPECT_EQ(body.surface.vertex_count(), 21 * 21);
  EXPECT_EQ(body.surface.triangle_count(), 2 * 20 * 20);
  EXPECT_NEAR(body.longest_edge, std::sqrt(2.0) * 0.004, 1e-15);
}

TEST(LaparoscopyScene, TheShippedScenesLoad) {
  const std::filesystem::path dir =
      std::filesystem::path(COHAPTIC_SOURCE_DIR) / "scenes/laparoscopy";
  const Model tissue = build_model(load_scene(dir / "tissue.yaml"));
  EXPECT_TRUE(std::holds_alternative<HomeSpringBody>(tissue.bodies[0]));
  const Model fem = build_model(load_scene(dir / "tissue_fem.yaml"));
  // The FEM slab's top face has the sheet's vertices.
  const auto& sheet = std::get<HomeSpringBody>(tissue.bodies[0]).surface.vertices;
  const auto& nodes = std::get<ElasticBody>(fem.bodies[0]).mesh.nodes;
  int matched = 0;
  for (Eigen::Index v = 0; v < sheet.cols(); ++v)
    for (Eigen::Index n = 0; n < nodes.cols(); ++n)
      if ((nodes.col(n) - sheet.col(v)).norm() < 1e-9) ++matched;
  EXPECT_EQ(matched, sheet.cols());
}

TEST(LaparoscopyScene, ATissueFromAFreeSurferFileIsScaledToMetres) {
  const std::filesystem::path data =
      std::filesystem::path(COHAPTIC_SOURCE_DIR) / "tests/data/mesh_io";
  const Scene scene = parse_scene(
      replaced(
          replaced(kTissueScene,
                   "surface: {grid: {min: [-40, -40, 0], size: [80, 80], divisions: [20, 20]}}",
                   "surface: {file: tet_surface.asc}"),
          "patch_radius: 12", "patch_radius: 20"),
      data / "tissue.yaml");
  EXPECT_EQ(std::get<HomeSpringObjectSpec>(scene.objects[0].body).surface_file,
            data / "tet_surface.asc");
  const Model model = build_model(scene);
  const auto& body = std::get<HomeSpringBody>(model.bodies[0]);
  ASSERT_EQ(body.surface.vertex_count(), 4);
  EXPECT_EQ(body.surface.vertices.col(1), Vector3d(0.0105, 0, 0));
  EXPECT_EQ(body.rings.ring(0).size(), 3u);
  const std::string missing = load_error(
      replaced(kTissueScene, "{grid: {min: [-40, -40, 0], size: [80, 80], divisions: [20, 20]}}",
               "{file: none.asc}"));
  EXPECT_NE(missing.find("tissue.yaml:6: objects[0].surface.file: surface file"), std::string::npos)
      << missing;
  EXPECT_NE(missing.find("none.asc"), std::string::npos) << missing;
}

TEST(LaparoscopyScene, MistakesAreNamedByFileLineAndKey) {
  EXPECT_NE(load_error(replaced(kTissueScene, "{name: probe, shape: probe, trocar: [-60, 0, 120]}",
                                "{name: probe, shape: probe}"))
                .find("tissue.yaml:11: tools[0]: missing required key 'trocar'"),
            std::string::npos)
      << load_error(replaced(kTissueScene, "{name: probe, shape: probe, trocar: [-60, 0, 120]}",
                             "{name: probe, shape: probe}"));
  EXPECT_NE(load_error(replaced(kTissueScene, "trocar: [-60, 0, 120]}",
                                "trocar: [-60, 0, 120], jaws: {length: 3}}"))
                .find("tissue.yaml:11: tools[0].jaws: a probe has no jaws"),
            std::string::npos);
  EXPECT_NE(load_error(replaced(kTissueScene, "shape: probe, trocar", "shape: point, trocar"))
                .find("tools[0].trocar: only an instrument"),
            std::string::npos);
  EXPECT_NE(load_error(replaced(kTissueScene, "open_angle_deg: 40", "open_angle_deg: 95"))
                .find("tools[1].jaws.open_angle_deg"),
            std::string::npos);
  EXPECT_NE(load_error(replaced(kTissueScene, "home: 100", "home: -1"))
                .find("tissue.yaml:7: objects[0].stiffness.home"),
            std::string::npos);
  EXPECT_NE(load_error(replaced(kTissueScene, "surface: {grid:", "surface: {file: a.asc, grid:"))
                .find("objects[0].surface: expected exactly one"),
            std::string::npos);
  EXPECT_NE(load_error(replaced(kTissueScene, "deformation: polynomial", "deformation: cubic"))
                .find("objects[0].display.deformation"),
            std::string::npos);
  // Caught when compiling: a patch smaller than a triangle.
  try {
    build_model(tissue_scene(replaced(kTissueScene, "patch_radius: 12", "patch_radius: 5")));
    ADD_FAILURE() << "a patch radius below the longest edge was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("tissue.yaml:4: objects[0].patch_radius"),
              std::string::npos)
        << e.what();
  }
}

TEST(HomeSpringSimulation, ProbeForceIsEq8AtTheVertexWhereTheShaftCrosses) {
  const Model model = build_model(tissue_scene());
  const auto& body = std::get<HomeSpringBody>(model.bodies[0]);
  HomeSpringSimulation simulation(body, 0, model.scene.tools, 100);
  const Vector3d pivot = model.scene.tools[0].instrument->trocar;

  // Above the tissue: the patch is already there (aimed at), nothing is pressed.
  simulation.set_tool(0, Vector3d(-0.005, 0.002, 0.01));
  simulation.step(0);
  ASSERT_NE(simulation.ir(0), nullptr);
  EXPECT_FALSE(simulation.pressing(0));
  EXPECT_EQ(simulation.force(0).force, Vector3d::Zero());
  EXPECT_EQ(simulation.ir(1), nullptr) << "the forceps user has not been set";

  std::mt19937 rng(13);
  std::uniform_real_distribution<double> across(-0.02, 0.02), depth(0.0005, 0.008);
  int rebuilt = 0;
  std::uint64_t epoch = simulation.ir(0)->ir.epoch;
  for (int poke = 0; poke < 200; ++poke) {
    const Vector3d tool(across(rng), across(rng), -depth(rng));
    simulation.set_tool(0, tool);
    simulation.step(0.001 * (poke + 1));
    const BruteCrossing crossing = brute_force_crossing(body, pivot, tool);
    ASSERT_GE(crossing.vertex, 0);
    ASSERT_TRUE(simulation.pressing(0));
    const Vector3d expected = -eq8_load(body, crossing.vertex, tool - crossing.point);
    const Vector3d felt = simulation.force(0).force;
    EXPECT_LT((felt - expected).norm(), 1e-12 * expected.norm())
        << "poke " << poke << ": " << felt.transpose() << " against " << expected.transpose();
    EXPECT_GT(felt.z(), 0) << "pushed in, pushed back";
    const auto& patch = std::get<HomeSpringPatch>(simulation.ir(0)->ir.body);
    EXPECT_FALSE(patch.grasp.active());
    EXPECT_EQ(patch.trocar_pivot, pivot);
    if (simulation.ir(0)->ir.epoch != epoch) ++rebuilt;
    EXPECT_GE(simulation.ir(0)->ir.epoch, epoch);
    epoch = simulation.ir(0)->ir.epoch;
  }
  EXPECT_GT(rebuilt, 100) << "a new IR for (nearly) every poke at a new vertex";

  // Staying at the same vertex builds no new IR.
  const Vector3d tool(0.0001, 0.0001, -0.002);
  simulation.set_tool(0, tool);
  simulation.step(1);
  const std::uint64_t held = simulation.ir(0)->ir.epoch;
  simulation.set_tool(0, tool + Vector3d(0, 0, -0.0001));
  EXPECT_FALSE(simulation.step(1.001).rebuilt);
  EXPECT_EQ(simulation.ir(0)->ir.epoch, held);
}

TEST(HomeSpringSimulation, ForcepsGraspPullBackAndLetGoOnButtonUp) {
  const Model model = build_model(tissue_scene());
  const auto& body = std::get<HomeSpringBody>(model.bodies[0]);
  const InstrumentSpec& forceps = *model.scene.tools[1].instrument;
  HomeSpringSimulation simulation(body, 0, model.scene.tools, 100);
  // The jaw junction 8.5 mm above the sheet: open jaws (40 degrees, 10 mm) reach 7.7 mm
  // down, so they close until cos(angle) = 0.85 before they meet the tissue.
  const Vector3d above(0.0012, -0.0007, 0.0085);
  double time = 0;
  simulation.set_tool(1, above, 0);
  simulation.step(time);
  EXPECT_FALSE(simulation.pressing(1));
  EXPECT_FALSE(simulation.jaws(1).grasping);
  int steps = 0;
  for (; steps < 100 && !simulation.jaws(1).grasping; ++steps) {
    simulation.set_tool(1, above, 1u);
    simulation.step(time += 0.001);
  }
  ASSERT_TRUE(simulation.jaws(1).grasping);
  // The shaft leans (its pivot is off to the side): a jaw tip at angle a from the axis is
  // L cos(a) |axis.z| below the junction (the opening is all but horizontal), so the jaws
  // meet the sheet at cos(a) = h / (L |axis.z|), and stop within one increment of it.
  const Vector3d axis = (above - forceps.trocar).normalized();
  const double contact_angle = std::acos(above.z() / (forceps.jaw_length * -axis.z()));
  for (const double angle : simulation.jaws(1).angle) {
    EXPECT_LE(angle, contact_angle + 0.01);
    EXPECT_GT(angle, contact_angle - forceps.closing_step - 0.01);
  }
  EXPECT_GT(steps, 5) << "the jaws closed in increments";
  const ForcepsJaws closed = simulation.jaws(1);
  EXPECT_NEAR(closed.grasp_point.z(), 0, 1e-12) << "grasped on the sheet";
  const auto& grasped = std::get<HomeSpringPatch>(simulation.ir(1)->ir.body);
  ASSERT_TRUE(grasped.grasp.active());
  EXPECT_EQ(grasped.grasp.tool_at_grasp, above);
  const int vertex = grasped.surface_vertex[static_cast<std::size_t>(grasped.grasp.vertex)];
  for (int v = 0; v < body.surface.vertex_count(); ++v)
    EXPECT_GE((body.surface.vertices.col(v) - closed.grasp_point).norm(),
              (body.surface.vertices.col(vertex) - closed.grasp_point).norm());

  // Pull up and aside, the button held: the grasp holds and the tool feels Eq. 8 back.
  for (int step = 1; step <= 80; ++step) {
    const Vector3d u(0.00002 * step, 0.00001 * step, 0.0001 * step);
    simulation.set_tool(1, above + u, 1u);
    EXPECT_FALSE(simulation.step(time += 0.001).rebuilt) << "the grasp's IR stands";
    ASSERT_TRUE(simulation.jaws(1).grasping);
    EXPECT_EQ(simulation.jaws(1).grasp_point, closed.grasp_point);
    EXPECT_TRUE(simulation.pressing(1));
    const Vector3d expected = -eq8_load(body, vertex, u);
    const Vector3d felt = simulation.force(1).force;
    EXPECT_LT((felt - expected).norm(), 1e-12 * expected.norm()) << "step " << step;
    EXPECT_LT(felt.dot(u), 0) << "the force points back against the pull";
  }
  // The display: the grasp point's nearest vertex has followed most of the 8 mm pull, the
  // rim beyond R = 20 mm has not moved.
  const Vector3d u_end(0.0016, 0.0008, 0.008);
  const Eigen::Matrix3Xd moved = simulation.displayed() - body.surface.vertices;
  const double r = (body.surface.vertices.col(vertex) - closed.grasp_point).norm();
  EXPECT_NEAR(moved.col(vertex).norm(), (1 - r * r / (0.02 * 0.02)) * u_end.norm(), 1e-12);
  for (int v = 0; v < body.surface.vertex_count(); ++v) {
    if ((body.surface.vertices.col(v) - closed.grasp_point).norm() >= 0.02) {
      EXPECT_EQ(moved.col(v), Vector3d::Zero());
    }
  }

  // Button up: the jaws open, a new IR without the grasp, nothing felt above the sheet.
  const std::uint64_t epoch = simulation.ir(1)->ir.epoch;
  simulation.set_tool(1, above + u_end, 0);
  EXPECT_TRUE(simulation.step(time += 0.001).rebuilt);
  EXPECT_FALSE(simulation.jaws(1).grasping);
  EXPECT_GT(simulation.ir(1)->ir.epoch, epoch);
  EXPECT_FALSE(std::get<HomeSpringPatch>(simulation.ir(1)->ir.body).grasp.active());
  EXPECT_FALSE(simulation.pressing(1));
  EXPECT_EQ(simulation.force(1).force, Vector3d::Zero());
  EXPECT_EQ(simulation.displayed(), body.surface.vertices);
}

TEST(HomeSpringSimulation, TheSceneChoosesTheDisplayDeformationLocalOrGlobal) {
  // The probe 5 mm into the sheet near its centre: Eq. 1 dents within R = 20 mm and leaves
  // the rim at rest; FFD (Eq. 7 on the lattice) moves the whole sheet, less far away.
  const Vector3d tool(0.001, 0.0005, -0.005);
  for (const std::string method : {"polynomial", "ffd"}) {
    const Model model = build_model(
        tissue_scene(replaced(kTissueScene, "deformation: polynomial", "deformation: " + method)));
    const auto& body = std::get<HomeSpringBody>(model.bodies[0]);
    HomeSpringSimulation simulation(body, 0, model.scene.tools, 100);
    simulation.set_tool(0, tool);
    simulation.step(0);
    ASSERT_TRUE(simulation.pressing(0));
    const BruteCrossing crossing =
        brute_force_crossing(body, model.scene.tools[0].instrument->trocar, tool);
    const double pull = (tool - crossing.point).norm();
    const Eigen::VectorXd moved = (simulation.displayed() - body.surface.vertices).colwise().norm();
    const double corner = moved(0);  // vertex 0: the sheet's corner at (-40, -40) mm, 57 mm away
    EXPECT_LE(moved.maxCoeff(), pull * (1 + 1e-12)) << method;
    EXPECT_GT(moved(crossing.vertex), 0.5 * pull) << method;
    if (method == "polynomial")
      EXPECT_EQ(corner, 0);
    else
      EXPECT_GT(corner, 1e-6) << "FFD moves the whole tissue";
  }
}

TEST(SceneSimulation, EachInstrumentGetsItsOwnPatchOnTheTissue) {
  const Model model = build_model(tissue_scene());
  SceneSimulation simulation(model, std::vector<ComplianceColumns*>{nullptr}, model.scene.tools,
                             SimulationOptions{});
  simulation.set_tool(0, Vector3d(-0.01, 0.0, -0.003));
  simulation.set_tool(1, Vector3d(0.01, 0.0, -0.003));
  simulation.step(0);
  ASSERT_TRUE(simulation.ir_changed(0) && simulation.ir_changed(1));
  for (int user = 0; user < 2; ++user) {
    const auto& patch = std::get<HomeSpringPatch>(simulation.ir(user)->ir.body);
    EXPECT_EQ(patch.trocar_pivot,
              model.scene.tools[static_cast<std::size_t>(user)].instrument->trocar);
    EXPECT_EQ(simulation.ir(user)->ir.user, user);
    EXPECT_TRUE(simulation.pressing(user));
    EXPECT_GT(simulation.force(user).force.z(), 0);
  }
}

TEST(SceneSimulation, ButtonZeroReachesTheForcepsAndClosesThem) {
  const Model model = build_model(tissue_scene());
  SceneSimulation simulation(model, std::vector<ComplianceColumns*>{nullptr}, model.scene.tools,
                             SimulationOptions{});
  const Vector3d above(0.0012, -0.0007, 0.0085);
  const auto& tissue = std::get<HomeSpringSimulation>(simulation.body(0));
  double time = 0;
  for (int step = 0; step < 30; ++step) {
    simulation.set_tool(1, above);  // no button: the jaws stay open
    simulation.step(time += 0.001);
  }
  EXPECT_FALSE(tissue.jaws(1).grasping);
  EXPECT_EQ(tissue.jaws(1).angle[0], model.scene.tools[1].instrument->open_angle);
  for (int step = 0; step < 30; ++step) {
    simulation.set_tool(1, above, 1u);
    simulation.step(time += 0.001);
  }
  EXPECT_TRUE(tissue.jaws(1).grasping);
  EXPECT_TRUE(std::get<HomeSpringPatch>(simulation.ir(1)->ir.body).grasp.active());
  EXPECT_TRUE(simulation.pressing(1));
  simulation.set_tool(1, above + Vector3d(0, 0, 0.003), 1u);
  simulation.step(time += 0.001);
  EXPECT_LT(simulation.force(1).force.z(), 0) << "pulled up, held down";
  simulation.set_tool(1, above, 0);
  simulation.step(time += 0.001);
  EXPECT_FALSE(tissue.jaws(1).grasping);
  EXPECT_FALSE(simulation.pressing(1));
}

}  // namespace
}  // namespace cohaptic
