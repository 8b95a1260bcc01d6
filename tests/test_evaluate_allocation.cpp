// The haptic path allocates nothing: malloc is interposed for this test program and
// counts the calls made while a flag is set, around thousands of evaluations of the FEM
// body's force (every contact model, the sphere model's too, remote tools, held boundary
// nodes), of a mass-spring body's sub-network integrated tick by tick with two tools
// pressing it, and of the laparoscopy model's per-tick functions (home-spring tick, alone
// and as the IR's body through evaluate_force, forceps step, display frames by both methods),
// and of the client's whole haptic loop while new mass-spring IRs of different sizes arrive,
// and of a separation body's instrument as the IR's body (a laser groove, a grasp that tears).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdlib>
#include <iostream>
#include <limits>

#include "client/haptic_loop.h"
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
#include "support/default_two_layers.h"
#include "support/evaluate_static.h"
#include "support/sanitizer_owns_malloc.h"
#include "support/test_meshes.h"
#include "support/tissue_sheet.h"

namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
}  // namespace

#ifdef COHAPTIC_SANITIZER_OWNS_MALLOC
#define REQUIRE_COUNTED_MALLOC() \
  GTEST_SKIP() << "a sanitizer owns malloc in this build: the plain build counts"
#else
extern "C" void* __libc_malloc(std::size_t size);  // glibc's own, behind the interposed one

// Every operator new, std::vector and Eigen heap allocation ends up here.
extern "C" void* malloc(std::size_t size) {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}

#define REQUIRE_COUNTED_MALLOC() \
  ASSERT_TRUE(cohaptic::interposition_counts()) << "malloc interposition is not active"
#endif

namespace cohaptic {
namespace {

// The counter works at all: a vector allocation inside the window is seen.
[[maybe_unused]] bool interposition_counts() {
  allocations = 0;
  counting = true;
  {
    volatile auto* probe = new std::vector<int>(100);
    delete probe;
  }
  counting = false;
  const bool seen = allocations.load() > 0;
  allocations = 0;
  return seen;
}

TEST(ForceEvaluator, AllocatesNothing) {
  REQUIRE_COUNTED_MALLOC();

  const Model model = build_model(parse_scene(testing::cube_scene_yaml(), "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(body.free_factor, body.dofs, body.surface.nodes);
  for (ContactModel contact_model :
       {ContactModel::node_translation, ContactModel::point_constraint}) {
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
  MassSpringSimulation simulation(body, 0, model.scene.tools, model.scene.haptic.force_limit_n,
                                  0.001);
  const Eigen::Vector3d middle(0.0434, 0, 0.0092);
  const Eigen::Vector3d own = middle + Eigen::Vector3d(0, 0, 0.0015),
                        other = own + Eigen::Vector3d(0.004, 0, 0);
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

// A device at scripted positions, read without allocating.
class PathDevice final : public HapticDevice {
 public:
  explicit PathDevice(std::vector<Eigen::Vector3d> path) : path_(std::move(path)) {}
  std::string describe() const override { return "path"; }
  DeviceState read(double) override {
    DeviceState state;
    state.position = path_[std::min(next_++, path_.size() - 1)];
    return state;
  }
  void write_force(const Eigen::Vector3d&, double) override {}
  double force_limit() const override { return 3.3; }

 private:
  std::vector<Eigen::Vector3d> path_;
  std::size_t next_ = 0;
};

// The client's haptic loop ticking on a driven clock (every tick on the 1 ms grid) while the
// noodle's IRs arrive as the I/O thread hands them over: a tool pressing the tube slides from
// its end towards its middle, so each IR's sub-network grows (sections cut off by the end
// come into it) and then keeps its size. Every tick (device, rings, the IR switch, the
// evaluation on the new IR's fresh state, the trace, the progress) allocates nothing: a new
// or bigger sub-network costs the haptic thread no allocation. The IRs are made and handed
// over between ticks, outside the count, as the I/O thread does them.
TEST(HapticLoop, TicksAllocateNothingWhileMassSpringIrsOfGrowingSubNetworksArrive) {
  const Model model = build_model(load_scene(testing::source_path("scenes/thin/noodle.yaml")));
  const MassSpringModel& body = std::get<MassSpringModel>(model.bodies.front());
  MassSpringSimulation simulation(body, 0, model.scene.tools, model.scene.haptic.force_limit_n,
                                  0.001);
  std::vector<Eigen::Vector3d> path;
  std::vector<IrSlot> slots;  // one every 10 ticks
  std::vector<int> node_counts;
  for (int i = 0; i < 600; ++i) {  // 0.6 s: from 2 mm to 26 mm along the tube, 1.5 mm into its top
    const Eigen::Vector3d tool(0.002 + 0.04 * i * 1e-3, 0,
                               0.0092 - 0.0015 * std::min(1.0, i / 100.0));
    path.push_back(tool);
    simulation.set_tool(0, tool);
    simulation.step(1e-3 * i);
    if (i % 10 == 0 && simulation.ir(0)) {
      slots.push_back(make_ir_slot(std::make_unique<const PreparedIR>(*simulation.ir(0)), 0));
      node_counts.push_back(std::get<MassSpringIr>(simulation.ir(0)->ir.body).node_count());
    }
  }
  ASSERT_GE(slots.size(), 50u);
  ASSERT_LT(*std::min_element(node_counts.begin(), node_counts.end()),
            *std::max_element(node_counts.begin(), node_counts.end()))
      << "the sub-network grows as the tool leaves the tube's end";

  struct Driven {
    std::int64_t now = 1'000'000'000;
    std::int64_t ticks = 0;
    HapticChannels* channels = nullptr;
    std::vector<IrSlot>* slots = nullptr;
    std::size_t next = 0;
  } driven;
  auto channels = std::make_unique<HapticChannels>();
  channels->tracing = true;
  driven.channels = channels.get();
  driven.slots = &slots;
  const HapticClock clock{
      [](void* c) { return static_cast<Driven*>(c)->now; },
      [](void* c, std::int64_t deadline) {
        auto& d = *static_cast<Driven*>(c);
        counting = false;  // the I/O thread's part: hand over the next IR, drain the rings
        if (d.ticks++ % 10 == 0 && d.next < d.slots->size()) {
          (*d.slots)[d.next].arrival_ns = deadline;  // fresh: no fading
          d.channels->ir.back() = std::move((*d.slots)[d.next++]);
          d.channels->ir.publish();
        }
        while (d.channels->trace.pop()) {
        }
        while (d.channels->own_samples.pop()) {
        }
        while (d.channels->events.pop()) {
        }
        d.now = deadline;
        counting = true;
      },
      &driven};
  PathDevice device(path);
  HapticLoopSettings settings;
  settings.duration_s = 0.59;
  settings.realtime = false;
  HapticLoop loop(device, *channels, settings, clock);
  REQUIRE_COUNTED_MALLOC();
  allocations = 0;
  loop.run(std::atomic<bool>{false});
  counting = false;
  EXPECT_EQ(allocations.load(), 0) << "a haptic tick allocated";
  EXPECT_GE(loop.metrics().ir_switches, slots.size() - 1);
  EXPECT_EQ(loop.metrics().non_finite, 0u);
  EXPECT_GT(loop.metrics().peak_force, 0) << "the tool pressed";
  std::cout << "sub-network nodes from " << node_counts.front() << " to " << node_counts.back()
            << ", " << slots.size() << " IRs, " << loop.metrics().ir_switches
            << " switches, peak force " << loop.metrics().peak_force << " N\n";
}

// The paired boxes (scenes/objects/paired_boxes.yaml): A's IR carries B's backing, which
// the client's evaluation integrates every substep.
TEST(ForceEvaluator, BackedMassSpringSubNetworkAllocatesNothing) {
  const Model model =
      build_model(load_scene(testing::source_path("scenes/objects/paired_boxes.yaml")));
  const SceneCompliance compliance = prepare_scene_compliance(model, true, std::nullopt);
  SceneSimulation simulation(model, compliance.per_body, model.scene.tools, SimulationOptions{});
  const Eigen::Vector3d tool(
      0, 0, 0.0535);  // its 2 mm radius about 2 mm into A's top (53.3 mm less its sag)
  for (int i = 0; i < 500; ++i) {
    simulation.set_tool(0, tool);
    simulation.step(0.001 * i);
  }
  ASSERT_NE(simulation.ir(0), nullptr);
  const PreparedIR& prepared = *simulation.ir(0);
  ASSERT_FALSE(std::get<MassSpringIr>(prepared.ir.body).backing.empty());
  EvaluationState state = make_evaluation_state(prepared);
  REQUIRE_COUNTED_MALLOC();
  double largest = 0;
  bool finite = true;
  counting = true;
  for (int i = 0; i < 2000; ++i) {
    const ForceSample sample =
        evaluate_force(prepared, state, tool - Eigen::Vector3d(0, 0, 2e-6 * (i % 1000)), {}, 0.001);
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
  const TissueDisplay polynomial =
      make_tissue_display(sheet.vertices, 0.01, DisplayDeformation::polynomial);
  const TissueDisplay lattice =
      make_tissue_display(sheet.vertices, 0.01, DisplayDeformation::ffd_one_point);
  Eigen::Matrix3Xd deformed(3, sheet.vertices.cols());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int touching = 0;
  counting = true;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d tool(0.008 * std::cos(1e-2 * i), 0.008 * std::sin(1e-2 * i),
                               0.003 - 6e-6 * i);
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

TEST(ForceEvaluator, SeparationBodyAllocatesNothing) {
  REQUIRE_COUNTED_MALLOC();
  const SeparationPatch& patch = testing::default_two_layers().patch;
  IntermediateRepresentation ir;
  ir.force_limit = 3.3;
  SeparationIr body;
  body.patch = std::make_shared<const SeparationPatch>(patch);
  body.state = make_separation_state(patch);
  body.tool.laser = true;
  ir.body = std::move(body);
  const PreparedIR client = prepare_ir(std::move(ir));
  EvaluationState state = make_evaluation_state(client);
  const Eigen::Vector3d from(0.0205, 0.012, 0.0002), to(0.0205, 0.028, 0.0002),
      rim(0, 0.02, 0.0002);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  counting = true;
  for (int i = 0; i <= 800; ++i)  // the groove at 20 mm/s, firing
    sum +=
        evaluate_force(client, state, from + (to - from) * (i / 800.0), {}, 1e-3, kLaserFireButton)
            .force;
  for (int i = 0; i <= 1000; ++i)  // jaws closed on the rim, pulled up 8 mm: it tears
    sum += evaluate_force(client, state, rim + Eigen::Vector3d(0, 0, 8e-6 * i), {}, 1e-3, 2).force;
  counting = false;
  EXPECT_EQ(allocations.load(), 0) << "the separation body's haptic path allocated";
  EXPECT_TRUE(sum.allFinite());
  EXPECT_GT(std::get<SeparationEvaluation>(state.body).state.separated_area,
            patch.spot_diameter * 0.016)
      << "the groove and the tear happened";
}

TEST(ForceEvaluator, AllocatesNothingUnderTheSphereModel) {
  testing::CubeSceneOptions cube;
  cube.tools = "[{name: A, shape: sphere, radius: 30}, {name: B, shape: sphere, radius: 30}]";
  const Model model = build_model(parse_scene(testing::cube_scene_yaml(cube), "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(body.free_factor, body.dofs, body.surface.nodes);
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
  EvaluationState state = make_evaluation_state(prepared);  // its contact solve, sized here
  ASSERT_TRUE(std::get<FemEvaluation>(state.body).sphere.has_value());
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
