// The haptic path allocates nothing: malloc is interposed for this test program and
// counts the calls made while a flag is set, around thousands of evaluations of the FEM
// body's force (every contact model, the sphere model's too, remote tools, held boundary
// nodes), of a mass-spring body's sub-network integrated tick by tick with two tools
// pressing it, and of the laparoscopy model's per-tick functions (home-spring tick, alone
// and as the IR's body through evaluate_force, forceps step, display frames by both methods).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdlib>
#include <limits>

#include "common/laparoscopy/extract_home_spring_patch.h"
#include "common/laparoscopy/forceps_jaws.h"
#include "common/laparoscopy/home_spring_contact.h"
#include "common/laparoscopy/tissue_display.h"
#include "common/model/scene_compliance.h"
#include "common/scene/load_scene.h"
#include "common/sim/scene_simulation.h"
#include "common/sim/mass_spring_simulation.h"
#include "common/sim/simulation.h"
#include "support/cube_scene.h"
#include "support/evaluate_static.h"
#include "support/sanitizer_owns_malloc.h"
#include "support/test_meshes.h"
#include "support/tissue_sheet.h"

namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
}  // namespace

#ifdef COHAPTIC_SANITIZER_OWNS_MALLOC
#define REQUIRE_COUNTED_MALLOC() GTEST_SKIP() << "a sanitizer owns malloc in this build: the plain build counts"
#else
extern "C" void* __libc_malloc(std::size_t size);  // glibc's own, behind the interposed one

// Every operator new, std::vector and Eigen heap allocation ends up here.
extern "C" void* malloc(std::size_t size) {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}

#define REQUIRE_COUNTED_MALLOC() ASSERT_TRUE(cohaptic::interposition_counts()) << "malloc interposition is not active"
#endif

namespace cohaptic {
namespace {

// The counter works at all: a vector allocation inside the window is seen.
[[maybe_unused]] bool interposition_counts() {
  allocations = 0;
  counting = true;
  { volatile auto* probe = new std::vector<int>(100); delete probe; }
  counting = false;
  const bool seen = allocations.load() > 0;
  allocations = 0;
  return seen;
}

TEST(ForceEvaluator, AllocatesNothing) {
  REQUIRE_COUNTED_MALLOC();

  const Model model = build_model(parse_scene(testing::cube_scene_yaml(), "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(*body.free_factor, body.dofs, body.surface.nodes);
  for (ContactModel contact_model : {ContactModel::node_translation, ContactModel::point_constraint}) {
    SimulationOptions options;
    options.ir.contact_model = contact_model;
    options.ir.patch_rings = 2;
    options.step_delay_nodes = 150;
    Simulation simulation(body, model.obstacles, columns, std::vector<ToolSpec>(2), options);
    simulation.set_tool(0, Eigen::Vector3d(-0.02, 0.005, -0.004));
    simulation.set_tool(1, Eigen::Vector3d(0.025, -0.005, -0.003));
    simulation.step(0);
    const PreparedIR& prepared = *simulation.ir(0);
    const std::vector<Eigen::Vector3d> remotes = simulation.remote_positions(prepared.ir);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    counting = true;
    for (int i = 0; i < 5000; ++i) {
      const Eigen::Vector3d tool(-0.02 + 1e-6 * (i % 1000), 0.005, -0.004 + 1e-7 * (i % 300));
      sum += testing::evaluate_static(prepared, tool, remotes).force;
    }
    counting = false;
    EXPECT_EQ(allocations.load(), 0) << "evaluate_force allocated";
    EXPECT_TRUE(sum.allFinite());
    EXPECT_GT(sum.norm(), 0);
  }
}

// The noodle (scenes/thin/noodle.yaml) pressed by two tools 4 mm apart: the IR of the
// first carries the second as a remote, and each tick integrates the sub-network.
TEST(ForceEvaluator, MassSpringSubNetworkAllocatesNothing) {
  const Model model = build_model(load_scene(testing::source_path("scenes/thin/noodle.yaml")));
  const MassSpringModel& body = std::get<MassSpringModel>(model.bodies.front());
  MassSpringSimulation simulation(body, 0, model.scene.tools, model.scene.haptic.force_limit_n, 0.001);
  const Eigen::Vector3d middle(0.0434, 0, 0.0092);
  const Eigen::Vector3d own = middle + Eigen::Vector3d(0, 0, 0.0015), other = own + Eigen::Vector3d(0.004, 0, 0);
  for (int i = 0; i < 20 && !simulation.ir(0); ++i) {
    simulation.set_tool(0, own);
    simulation.set_tool(1, other);
    simulation.step(0.001 * i);
  }
  ASSERT_NE(simulation.ir(0), nullptr);
  const PreparedIR& prepared = *simulation.ir(0);
  ASSERT_EQ(remote_count(prepared.ir), 1);
  EvaluationState state = make_evaluation_state(prepared);
  const std::array<Eigen::Vector3d, 1> remotes{other - Eigen::Vector3d(0, 0, 0.002)};
  REQUIRE_COUNTED_MALLOC();
  double largest = 0;
  bool finite = true;
  counting = true;
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d tool = own - Eigen::Vector3d(1e-6 * (i % 1000), 0, 2e-6 * (i % 1500));
    const ForceSample sample = evaluate_force(prepared, state, tool, remotes, 0.001);
    finite = finite && sample.force.allFinite();
    largest = std::max(largest, sample.force.norm());
  }
  counting = false;
  EXPECT_EQ(allocations.load(), 0) << "evaluate_force allocated on a mass-spring body";
  EXPECT_TRUE(finite);
  EXPECT_GT(largest, 0) << "the tool pressed";
}

// The paired boxes (scenes/objects/paired_boxes.yaml): A's IR carries B's backing, which
// the client's evaluation integrates every substep.
TEST(ForceEvaluator, BackedMassSpringSubNetworkAllocatesNothing) {
  const Model model = build_model(load_scene(testing::source_path("scenes/objects/paired_boxes.yaml")));
  const SceneCompliance compliance = prepare_scene_compliance(model, true, std::nullopt);
  SceneSimulation simulation(model, compliance.per_body, model.scene.tools, SimulationOptions{});
  const Eigen::Vector3d tool(0, 0, 0.0535);  // its 2 mm radius about 2 mm into A's top (53.3 mm less its sag)
  for (int i = 0; i < 500; ++i) {
    simulation.set_tool(0, tool);
    simulation.step(0.001 * i);
  }
  ASSERT_NE(simulation.ir(0), nullptr);
  const PreparedIR& prepared = *simulation.ir(0);
  ASSERT_FALSE(std::get<MassSpringIr>(prepared.ir.body).backing.empty());
  EvaluationState state = make_evaluation_state(prepared);
  ASSERT_TRUE(interposition_counts()) << "malloc interposition is not active";
  double largest = 0;
  bool finite = true;
  counting = true;
  for (int i = 0; i < 2000; ++i) {
    const ForceSample sample = evaluate_force(prepared, state, tool - Eigen::Vector3d(0, 0, 2e-6 * (i % 1000)), {}, 0.001);
    finite = finite && sample.force.allFinite();
    largest = std::max(largest, sample.force.norm());
  }
  counting = false;
  EXPECT_EQ(allocations.load(), 0) << "evaluate_force allocated on a backed mass-spring body";
  EXPECT_TRUE(finite);
  EXPECT_GT(largest, 0) << "the tool pressed";
}

TEST(LaparoscopyHapticPath, AllocatesNothing) {
  REQUIRE_COUNTED_MALLOC();
  const TriangleSurface sheet = testing::equilateral_sheet(40, 40, 0.002);
  const VertexRings rings = vertex_rings(sheet.triangles, sheet.vertex_count());
  const Eigen::Vector3d pivot(0.01, 0.02, 0.15);
  const PreparedHomeSpringPatch prepared = prepare_home_spring_patch(extract_home_spring_patch(
      {sheet.vertices, sheet.triangles, rings}, Eigen::Vector3d::Zero(), 0.02, {300, 100}, pivot));
  IntermediateRepresentation ir;  // the same patch as the client receives it, as the IR's body
  ir.force_limit = 5;
  ir.body = prepared.patch;
  const PreparedIR client = prepare_ir(std::move(ir));
  EvaluationState client_state = make_evaluation_state(client);
  const AabbTree sheet_tree(sheet.vertices, sheet.triangles);
  const ForcepsGeometry geometry{0.01, 0.5, 0.01};
  ForcepsJaws jaws = open_forceps(geometry);
  const TissueDisplay polynomial = make_tissue_display(sheet.vertices, 0.01, DisplayDeformation::polynomial);
  const TissueDisplay lattice = make_tissue_display(sheet.vertices, 0.01, DisplayDeformation::ffd_one_point);
  Eigen::Matrix3Xd deformed(3, sheet.vertices.cols());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int touching = 0;
  counting = true;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d tool(0.008 * std::cos(1e-2 * i), 0.008 * std::sin(1e-2 * i), 0.003 - 6e-6 * i);
    const HomeSpringContact contact = evaluate_home_spring(prepared, tool);
    sum += contact.force + evaluate_force(client, client_state, tool, {}, 1.0 / 2000).force;
    touching += contact.touching ? 1 : 0;
    if (const auto shaft = shaft_frame(pivot, tool, Eigen::Vector3d::UnitX()))
      step_forceps(geometry, *shaft, i % 500 < 400, sheet_tree, jaws);
    if (i % 100 == 0) {  // a display frame every 100 ticks
      display_tissue(polynomial, contact.contact_point, tool, deformed);
      display_tissue(lattice, contact.contact_point, tool, deformed);
    }
  }
  counting = false;
  EXPECT_EQ(allocations.load(), 0) << "the laparoscopy haptic path allocated";
  EXPECT_TRUE(sum.allFinite());
  EXPECT_GT(touching, 500);  // the tool does go through the sheet
}

TEST(ForceEvaluator, AllocatesNothingUnderTheSphereModel) {
  testing::CubeSceneOptions cube;
  cube.tools = "[{name: A, shape: sphere, radius: 30}, {name: B, shape: sphere, radius: 30}]";
  const Model model = build_model(parse_scene(testing::cube_scene_yaml(cube), "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(*body.free_factor, body.dofs, body.surface.nodes);
  SimulationOptions options;
  options.ir.contact_model = ContactModel::sphere;
  options.ir.patch_rings = 2;
  options.step_delay_nodes = 150;
  Simulation simulation(body, model.obstacles, columns, model.scene.tools, options);
  simulation.set_tool(0, Eigen::Vector3d(-0.02, 0.005, 0.026));
  simulation.set_tool(1, Eigen::Vector3d(0.025, -0.005, 0.027));
  simulation.step(0);
  const PreparedIR& prepared = *simulation.ir(0);
  const std::vector<Eigen::Vector3d> remotes = simulation.remote_positions(prepared.ir);
  EvaluationState state = make_evaluation_state(prepared);  // the warm start, sized here
  ASSERT_TRUE(std::holds_alternative<SphereWarmStart>(state.body));
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  allocations = 0;
  counting = true;
  for (int i = 0; i < 5000; ++i) {
    const Eigen::Vector3d tool(-0.02 + 1e-6 * (i % 1000), 0.005, 0.026 - 1e-7 * (i % 300));
    sum += evaluate_force(prepared, state, tool, remotes, 1e-3).force;
  }
  counting = false;
  EXPECT_EQ(allocations.load(), 0) << "evaluate_force allocated";
  EXPECT_TRUE(sum.allFinite());
  EXPECT_GT(sum.norm(), 0);
}

}  // namespace
}  // namespace cohaptic
