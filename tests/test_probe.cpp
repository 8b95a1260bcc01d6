// The probe's static contact forces on the paper's cube: condensation against the full
// sparse solve and against an independent FEM, physical properties of the answer, and the
// command-line program itself (its JSON, its exports, its errors).
#include <gtest/gtest.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cmath>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <limits>
#include <random>

#include "common/mesh/read_gmsh.h"
#include "common/model/compliance_setup.h"
#include "common/model/model.h"
#include "common/model/static_contact.h"
#include "common/sim/simulation.h"
#include "common/scene/load_scene.h"
#include "support/independent_fem.h"
#include "support/run_program.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

namespace fs = std::filesystem;

class CubeProbe : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    model_ = new Model(build_model(load_scene(testing::source_path("scenes/cube.yaml"))));
    const ElasticBody& body = single_elastic_body(*model_);
    columns_ =
        new ComplianceColumns(body.free_factor, body.dofs, compliance_row_nodes(body, false));
  }
  static void TearDownTestSuite() {
    delete columns_;
    delete model_;
  }
  static Eigen::Vector3d mm(double x, double y, double z) {
    return Eigen::Vector3d(x, y, z) * 1e-3;
  }
  // The IR path: one simulation step with these tools, each user's force from its IR.
  static std::vector<ToolReaction> condensed(const std::vector<PressedTool>& tools) {
    const std::vector<ContactQuery> contacts = find_tool_contacts(body(), tools);
    SimulationOptions options;
    options.ir.force_limit = std::numeric_limits<double>::infinity();
    Simulation simulation(body(), model_->obstacles, *columns_, std::vector<ToolSpec>(tools.size()),
                          options);
    for (std::size_t t = 0; t < tools.size(); ++t)
      simulation.set_tool(static_cast<int>(t), tools[t].position);
    simulation.step(0);
    std::vector<ToolReaction> reactions(tools.size());
    for (std::size_t t = 0; t < tools.size(); ++t) {
      reactions[t].query = contacts[t];
      reactions[t].reaction = simulation.force(static_cast<int>(t)).force;
    }
    return reactions;
  }
  static const ElasticBody& body() { return single_elastic_body(*model_); }
  static Model* model_;
  static ComplianceColumns* columns_;
};
Model* CubeProbe::model_ = nullptr;
ComplianceColumns* CubeProbe::columns_ = nullptr;

// Random points under the front face, inside the touchable region.
std::vector<PressedTool> random_presses(std::mt19937& rng, int count, double max_depth_mm) {
  std::uniform_real_distribution<double> across(-60, 60), depth(0.2, max_depth_mm);
  std::vector<PressedTool> tools;
  for (int i = 0; i < count; ++i)
    tools.push_back({Eigen::Vector3d(across(rng), across(rng), -depth(rng)) * 1e-3, 0});
  return tools;
}

TEST_F(CubeProbe, CondensedForcesEqualTheFullSparseSolve) {
  std::mt19937 rng(42);
  for (int trial = 0; trial < 20; ++trial) {
    const auto tools = random_presses(rng, 1 + trial % 2, 10);
    std::vector<ContactQuery> contacts;
    try {
      contacts = find_tool_contacts(body(), tools);
    } catch (const Error&) {
      continue;  // two random tools on neighbouring triangles: not this test's subject
    }
    const auto fast = condensed(tools);
    const auto reference =
        contact_reactions_reference(body(), contacts, {}, ContactModel::node_translation);
    for (std::size_t t = 0; t < tools.size(); ++t) {
      ASSERT_TRUE(fast[t].query.contact.has_value());
      EXPECT_LE((fast[t].reaction - reference[t].reaction).norm(),
                1e-9 * reference[t].reaction.norm());
    }
  }
}

TEST_F(CubeProbe, ForcesAgreeWithAnIndependentFemOfTheSameMesh) {
  std::mt19937 rng(7);
  const auto tools = random_presses(rng, 1, 8);
  const auto contacts = find_tool_contacts(body(), tools);
  const auto fast = condensed(tools);

  std::vector<bool> fixed(static_cast<std::size_t>(3 * body().mesh.node_count()));
  for (int dof = 0; dof < 3 * body().mesh.node_count(); ++dof)
    fixed[dof] = body().dofs.free_index[dof] < 0;
  std::map<int, double> prescribed;
  const ToolContact& contact = *contacts[0].contact;
  const Triangle& tri = body().surface.triangles[contact.triangle];
  for (int node : tri)
    for (int a = 0; a < 3; ++a) prescribed[3 * node + a] = contact.displacement[a];
  const auto independent =
      testing::independent_static_solve(body().mesh, 1.0e6, 0.4, fixed, prescribed);
  Eigen::Vector3d expected = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i)
    expected -= contact.weights[i] * independent.reaction.segment<3>(3 * tri[i]);
  EXPECT_LE((fast[0].reaction - expected).norm(), 1e-8 * expected.norm())
      << "probe " << fast[0].reaction.transpose() << " independent " << expected.transpose();
}

TEST_F(CubeProbe, TheForcePushesTheToolOutAndIsLinearInDepth) {
  const auto shallow = condensed({{mm(1, 2, -2), 0}});
  const auto deep = condensed({{mm(1, 2, -6), 0}});
  ASSERT_TRUE(shallow[0].query.contact && deep[0].query.contact);
  EXPECT_EQ(shallow[0].query.contact->triangle, deep[0].query.contact->triangle);
  EXPECT_GT(shallow[0].reaction.z(), 0);  // out of the front face, towards +z
  EXPECT_GT(shallow[0].reaction.z(), 5 * shallow[0].reaction.head<2>().norm());
  EXPECT_LE((deep[0].reaction - 3 * shallow[0].reaction).norm(), 1e-10 * deep[0].reaction.norm());
  EXPECT_NEAR(shallow[0].query.contact->depth, 2e-3, 1e-15);
}

TEST_F(CubeProbe, TwoToolsCoupleThroughTheObject) {
  const PressedTool a{mm(-20, 0, -5), 0}, b{mm(20, 0, -5), 0};
  const auto alone = condensed({a});
  const auto together = condensed({a, b});
  // Pressing the same way next to it makes the surface around A sink: A needs less force.
  EXPECT_LT(together[0].reaction.z(), alone[0].reaction.z());
  EXPECT_GT(alone[0].reaction.z() - together[0].reaction.z(), 0.01 * alone[0].reaction.z());
  EXPECT_THROW(condensed({a, {mm(-20, 0.5, -5), 0}}), Error);  // same triangle: cannot both hold it
}

TEST_F(CubeProbe, AToolOutsideOrBesideTheTouchableFaceHasNoForce) {
  const auto reactions = condensed({{mm(0, 0, 3), 0}, {mm(80, 0, -50), 0}});
  EXPECT_FALSE(reactions[0].query.contact);
  EXPECT_NEAR(reactions[0].query.signed_distance, 3e-3, 1e-12);
  EXPECT_FALSE(reactions[1].query.contact);
  EXPECT_EQ(reactions[1].reaction, Eigen::Vector3d::Zero());
}

// --- the program ---

testing::ProgramRun run(const std::string& arguments) {
  return testing::run_program(COHAPTIC_LAB_EXE, arguments);
}

TEST_F(CubeProbe, TheProgramPrintsOneJsonObjectWithTheSameForces) {
  const fs::path dir = fs::temp_directory_path() / ("cohaptic-probe-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const testing::ProgramRun result =
      run("probe --scene " + testing::source_path("scenes/cube.yaml") +
          " --tool 5,-7,-4 --tool -30,40,-2 --tool 0,0,10 --json --no-disk-cache --export-msh " +
          (dir / "cube.msh").string() + " --export-vtu " + (dir / "cube.vtu").string());
  ASSERT_EQ(result.exit_code, 0) << result.out;
  const nlohmann::json json =
      nlohmann::json::parse(result.out);  // throws if stdout holds anything else
  EXPECT_EQ(json["nodes"], 1728);
  EXPECT_EQ(json["tets"], 7986);
  EXPECT_EQ(json["fixed_nodes"].size(), 144u);
  ASSERT_EQ(json["tools"].size(), 3u);
  EXPECT_TRUE(json["timings_ms"].contains("load") && json["timings_ms"].contains("precompute") &&
              json["timings_ms"].contains("solve"));

  const auto expected = condensed({{mm(5, -7, -4), 0}, {mm(-30, 40, -2), 0}, {mm(0, 0, 10), 0}});
  const GmshMesh exported = read_gmsh(dir / "cube.msh");
  for (int t = 0; t < 2; ++t) {
    const nlohmann::json& tool = json["tools"][t];
    Eigen::Vector3d force(tool["force"][0], tool["force"][1], tool["force"][2]);
    EXPECT_LE((force - expected[t].reaction).norm(), 1e-12 * expected[t].reaction.norm());
    // The ids name the same nodes in the exported mesh, whose coordinates are in mm.
    const Triangle& tri = body().surface.triangles[expected[t].query.contact->triangle];
    for (int i = 0; i < 3; ++i) {
      const std::int64_t id = tool["contact"]["triangle"][i];
      EXPECT_EQ(id, body().mesh.node_tags[tri[i]]);
      const int index = node_index_from_tag(exported.mesh, id);
      ASSERT_GE(index, 0);
      EXPECT_LE((exported.mesh.nodes.col(index) * 1e-3 - body().mesh.nodes.col(tri[i])).norm(),
                1e-15);
      const double dz = tool["contact"]["displacement"][i][2];
      EXPECT_NEAR(dz, t == 0 ? -4.0 : -2.0, 1e-9);
    }
  }
  EXPECT_TRUE(json["tools"][2]["contact"].is_null());
  EXPECT_GT(fs::file_size(dir / "cube.vtu"), 100000u);
  fs::remove_all(dir);
}

// On a scene of sphere tools the program names the sphere model, and --reference solves the
// sphere model's unilateral problem in full (SphereContactReference), which the IR answers
// exactly: both spheres' forces agree to 1e-9 (the point model's would not).
// Tool t's force in `cohaptic-lab probe --json`'s output [N].
Eigen::Vector3d probed_force(const nlohmann::json& json, int t) {
  const nlohmann::json& f = json["tools"][t]["force"];
  return Eigen::Vector3d(f[0], f[1], f[2]);
}

// Two 40 mm spheres pressing the cube's top face, answered as JSON.
std::string two_sphere_probe() {
  return "probe --scene " + testing::source_path("scenes/tradeoff/cube_two_spheres.yaml") +
         " --tool 30,25,36 --tool -20,-10,37 --json --no-disk-cache";
}

// Runs `cohaptic-lab ARGUMENTS` and parses its JSON (failing the test on a non-zero exit).
nlohmann::json probe_json_of(const std::string& arguments) {
  const testing::ProgramRun probe = run(arguments);
  EXPECT_EQ(probe.exit_code, 0) << probe.out;
  return probe.exit_code == 0 ? nlohmann::json::parse(probe.out) : nlohmann::json();
}

// Both tools of two_sphere_probe press the top face and feel the same in `actual` as in
// `expected`, to 1e-9.
void expect_same_two_sphere_forces(const nlohmann::json& expected, const nlohmann::json& actual) {
  for (int t = 0; t < 2; ++t) {
    const Eigen::Vector3d force = probed_force(expected, t);
    EXPECT_GT(force.z(), 1.0) << "tool " << t << " presses the cube's top face";
    EXPECT_LE((probed_force(actual, t) - force).norm(), 1e-9 * force.norm()) << "tool " << t;
  }
}

TEST(ProbeProgram, OnASphereSceneItsReferenceIsTheSphereModelsFullSolve) {
  const nlohmann::json by_ir = probe_json_of(two_sphere_probe()),
                       by_reference = probe_json_of(two_sphere_probe() + " --reference");
  ASSERT_FALSE(by_ir.is_null() || by_reference.is_null());
  EXPECT_EQ(by_ir["contact_model"], "sphere");
  EXPECT_EQ(by_reference["method"], "reference");
  expect_same_two_sphere_forces(by_reference, by_ir);
}

// Without obstacles or held nodes the sphere model's answer depends on the positions only,
// so an approach in steps (each tool from touching to its position, then settling) ends where
// one step from rest does.
TEST(ProbeProgram, AnApproachInStepsEndsWhereOneStepDoesWhenNothingIsHeldOnTheWay) {
  const nlohmann::json by_one = probe_json_of(two_sphere_probe()),
                       by_steps = probe_json_of(two_sphere_probe() + " --approach-steps 6");
  ASSERT_FALSE(by_one.is_null() || by_steps.is_null());
  EXPECT_EQ(by_one["tools"][0]["ir"]["steps"], 1);
  EXPECT_GE(by_steps["tools"][0]["ir"]["steps"], 6);
  expect_same_two_sphere_forces(by_one, by_steps);
}

// A 10 mm sphere pressed 0.5 and 1 mm into the block that gmsh grades to 0.6 mm under it
// (scenes/block/two_spheres.yaml, one tool): the probe serves its IR (a few hundred row
// nodes, no cap) and lands within 5 % of Hertz (F = 4/3 E / (1 - nu^2) sqrt(R) d^1.5, E =
// 100 kPa, nu = 0.3); pressed 1 mm, the same block graded to 1.2 mm (two_spheres_coarse.yaml)
// agrees to 5 % (0.5 mm deep its contact spans two of its cells, and it is 5.5 % stiffer).
TEST(ProbeProgram, ASpherePressedIntoTheGradedBlockLandsWithinFivePercentOfHertzOnBothMeshes) {
  const auto force_at = [](const char* scene, double depth_mm) {
    const nlohmann::json json = probe_json_of(fmt::format(
        "probe --scene {} --tool=-25,0,{} --json", testing::source_path(scene), 10 - depth_mm));
    EXPECT_EQ(json["contact_model"], "sphere");
    return json.is_null() ? 0.0 : probed_force(json, 0).z();
  };
  for (const double depth_mm : {0.5, 1.0}) {
    const double depth = depth_mm * 1e-3,
                 hertz = 4.0 / 3.0 * 1e5 / (1 - 0.3 * 0.3) * std::sqrt(0.01) * std::pow(depth, 1.5);
    const double fine = force_at("scenes/block/two_spheres.yaml", depth_mm);
    const double coarse = force_at("scenes/block/two_spheres_coarse.yaml", depth_mm);
    std::printf(
        "  %.1f mm deep: 0.6 mm mesh %.4f N, 1.2 mm mesh %.4f N, Hertz %.4f N (%.3f, %.3f)\n",
        depth_mm, fine, coarse, hertz, fine / hertz, coarse / hertz);
    EXPECT_NEAR(fine / hertz, 1, 0.05) << depth_mm << " mm";
    if (depth_mm == 1.0) {
      EXPECT_NEAR(coarse / fine, 1, 0.05);
    }
  }
}

TEST(ProbeProgram, BadInputGivesAClearErrorAndANonZeroExit) {
  const std::string cube = testing::source_path("scenes/cube.yaml");
  EXPECT_EQ(run("probe --scene " + cube + " --tool 1,2").exit_code, 2);
  EXPECT_NE(run("probe --scene /no/such/scene.yaml --tool 1,2,3").exit_code, 0);
  EXPECT_NE(run("probe --scene " + cube + " --tool nan,0,0").exit_code, 0);
  EXPECT_NE(run("probe --scene " + cube + " --tool 1,2,3 --approach-steps 0").exit_code, 0);
  const std::string usage = run("probe --help").out;
  EXPECT_NE(usage.find("--export-vtu"), std::string::npos);
  EXPECT_NE(usage.find("--separately"), std::string::npos);
}

}  // namespace
}  // namespace cohaptic
