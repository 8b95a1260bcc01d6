// The force evaluator allocates nothing: malloc is interposed for this test program and
// counts the calls made while a flag is set, around thousands of evaluations with every
// contact model (the sphere model's too), remote tools and held boundary nodes.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <limits>

#include "common/scene/load_scene.h"
#include "common/sim/simulation.h"
#include "support/cube_scene.h"
#include "support/evaluate_static.h"

extern "C" void* __libc_malloc(std::size_t size);  // glibc's own, behind the interposed one

namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
}  // namespace

// Every operator new, std::vector and Eigen heap allocation ends up here.
extern "C" void* malloc(std::size_t size) {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}

namespace cohaptic {
namespace {

TEST(ForceEvaluator, AllocatesNothing) {
  // Check the counter works at all: a vector allocation inside the window is seen.
  counting = true;
  { volatile auto* probe = new std::vector<int>(100); delete probe; }
  counting = false;
  ASSERT_GT(allocations.load(), 0) << "malloc interposition is not active";
  allocations = 0;

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
