// The live view on every body kind a scene can have (view/shown_scene.h, body_frame_state.h):
// the shipped scenes of a mass-spring noodle, of two objects (a mass-spring box on an FEM box),
// of an FEM pair (a slab pressing a block), of a laparoscopy tissue and of separating tissue,
// stepped by SceneSimulation as the server steps them. Each frame's displacement is checked against
// what the body's own simulation says by another way: a mass-spring node's state position minus its
// rest position, an FEM body's displacement_of (the display's gathered solve, not the view's loaded
// columns), the tissue's displayed() surface; the separating tissue, which has no displacement
// field, is drawn at rest with both layers' boundary surfaces.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "common/mesh/boundary_surface.h"
#include "common/model/model.h"
#include "common/model/scene_compliance.h"
#include "common/scene/load_scene.h"
#include "common/sim/elastic_states.h"
#include "common/sim/scene_simulation.h"
#include "support/test_meshes.h"
#include "view/view_messages.h"

namespace cohaptic {
namespace {

// A shipped scene as the server runs it, its first tools pressing.
struct ViewedShippedScene {
  Model model;
  SceneCompliance compliance;
  SceneSimulation simulation;
  view::ShownScene shown;
  std::vector<Eigen::Vector3d> tools;  // of the users pressing, from user 0 on
  double time = 0;

  explicit ViewedShippedScene(const Scene& scene)
      : model(build_model(scene)),
        compliance(prepare_scene_compliance(model, true, std::nullopt)),
        simulation(model, compliance.per_body, model.scene.tools, SimulationOptions{}),
        shown(view::shown_scene(model, compliance.per_body)) {}

  // Each tool k from 4 mm above targets[k] down to it over `seconds`, moving to the end (a
  // mass-spring surface is pressed by a tool that comes from outside, and stays pressed
  // while the tool goes on into it); the other tools away.
  void press(const std::vector<Eigen::Vector3d>& targets, double seconds) {
    tools = targets;
    const int steps = static_cast<int>(seconds * 1000);
    for (int k = 1; k <= steps; ++k) {
      for (std::size_t user = 0; user < targets.size(); ++user) {
        tools[user] =
            targets[user] + Eigen::Vector3d(0, 0, 0.004 * (1 - static_cast<double>(k) / steps));
        simulation.set_tool(static_cast<int>(user), tools[user]);
      }
      simulation.step(time += 0.001);
    }
  }
  view::Frame frame() {
    std::vector<view::ToolState> shown_tools(static_cast<std::size_t>(simulation.user_count()));
    std::vector<Eigen::Vector3d> forces(shown_tools.size(), Eigen::Vector3d::Zero());
    for (std::size_t user = 0; user < tools.size(); ++user) {
      shown_tools[user] = {true, tools[user]};
      forces[user] = simulation.force(static_cast<int>(user)).force;
    }
    const view::FrameState state = view::frame_state(
        simulation, compliance.per_body, solve_elastic_states(simulation), shown_tools, forces);
    return view::view_frame(state, shown, 1, time, 1000);
  }
};

Scene load_shipped_view_scene(const std::string& relative) {
  return load_scene(testing::source_path(relative));
}

// A frame's displacement of `part`'s nodes, one column per node [m].
Eigen::Matrix3Xd frame_part_displacement(const view::Frame& frame, const view::ShownPart& part) {
  Eigen::Matrix3Xd u(3, part.size());
  for (int k = 0; k < part.size(); ++k)
    for (int axis = 0; axis < 3; ++axis)
      u(axis, k) = frame.displacement(3 * (part.offset + k) + axis);
  return u;
}

// The Scene's rest positions and triangles are the shown scene's, every index in range.
void expect_view_scene_is_shown(const view::Scene& scene, const view::ShownScene& shown) {
  ASSERT_EQ(scene.rest_positions_size(), 3 * shown.node_count());
  for (int i = 0; i < scene.rest_positions_size(); ++i)
    EXPECT_EQ(scene.rest_positions(i), static_cast<float>(shown.rest.data()[i])) << i;
  ASSERT_EQ(scene.triangles_size(), 3 * static_cast<int>(shown.triangles.size()));
  for (std::uint32_t corner : scene.triangles())
    EXPECT_LT(corner, static_cast<std::uint32_t>(shown.node_count()));
}

// A mass-spring body's shown nodes are its surface nodes, displaced to their state's positions.
void expect_view_network_shown(const view::Frame& frame, const view::ShownPart& part,
                               const MassSpringSimulation& body) {
  EXPECT_EQ(part.nodes, body.body().network.surface_nodes);
  const Eigen::Matrix3Xd u = frame_part_displacement(frame, part);
  Eigen::Matrix3Xd expected(3, part.size());
  for (int k = 0; k < part.size(); ++k) {
    const int node = part.nodes[static_cast<std::size_t>(k)];
    expected.col(k) =
        body.state().positions.col(node) - body.body().network.rest_positions.col(node);
  }
  const double largest = expected.cwiseAbs().maxCoeff();
  EXPECT_GT(largest, 1e-4) << "the press moved the network";
  EXPECT_LT((u - expected).cwiseAbs().maxCoeff(), 1e-6 * largest);
}

TEST(ViewBodies, TheNoodlesFrameShowsItsNodesPositionsMinusRestTheIrsPatchAndTheDrivenNode) {
  ViewedShippedScene noodle(load_shipped_view_scene("scenes/thin/noodle.yaml"));
  const auto& body = std::get<MassSpringSimulation>(noodle.simulation.body(0));
  const MassSpringNetwork& network = body.body().network;
  ASSERT_EQ(noodle.shown.parts.size(), 1u);
  EXPECT_EQ(noodle.shown.triangles.size(),
            network.triangles.size());  // every node of a triangle is a surface node
  expect_view_scene_is_shown(view::view_scene(noodle.model, noodle.shown, wire::P1, {}, 30, "live"),
                             noodle.shown);
  // The 2 mm sphere midway along, down to 7 mm: the soft noodle sags under its weight from
  // its top face at 9.2 mm to about 6.7 mm in the first 0.1 s, and is pressed 1-2 mm.
  noodle.press({Eigen::Vector3d(0.043, 0, 0.007)}, 0.2);
  // The driven node's contact comes and goes as the network relaxes under a tool held still:
  // on down, 0.05 mm a step, to a step that presses.
  for (int k = 0; k < 20 && !noodle.simulation.pressing(0); ++k) {
    noodle.tools[0].z() -= 5e-5;
    noodle.simulation.set_tool(0, noodle.tools[0]);
    noodle.simulation.step(noodle.time += 0.001);
  }
  ASSERT_TRUE(noodle.simulation.pressing(0));
  ASSERT_NE(noodle.simulation.ir(0), nullptr);
  const view::Frame frame = noodle.frame();
  ASSERT_EQ(frame.displacement_size(), 3 * noodle.shown.node_count());
  expect_view_network_shown(frame, noodle.shown.parts[0], body);
  // The IR's sub-network, as far as it is on the surface: shown, and around the tool.
  const view::UserFrame& user = frame.users(0);
  EXPECT_TRUE(user.pressing());
  ASSERT_GT(user.patch_nodes_size(), 0);
  // Its contact: the node the tool drives, on the surface.
  const int driven = body.reaction(0).node;
  ASSERT_EQ(user.contact_nodes_size(), 1);
  EXPECT_EQ(user.contact_nodes(0), static_cast<std::uint32_t>(noodle.shown.of_node(0, driven)));
  for (std::uint32_t shown : user.patch_nodes())
    EXPECT_LT(std::abs(noodle.shown.rest(0, shown) - noodle.tools[0].x()), 0.02) << shown;
  EXPECT_EQ(frame.boundary_nodes(), 0u);
}

TEST(ViewBodies, ThePairedBoxesShowTheNetworkAndTheElasticBoxEachFromItsOwnState) {
  ViewedShippedScene boxes(load_shipped_view_scene("scenes/objects/paired_boxes.yaml"));
  ASSERT_EQ(boxes.shown.parts.size(), 2u);
  const auto& front = std::get<MassSpringSimulation>(boxes.simulation.body(0));
  auto& behind = std::get<Simulation>(boxes.simulation.body(1));
  const view::ShownPart& box = boxes.shown.parts[1];
  EXPECT_EQ(box.offset, static_cast<int>(front.body().network.surface_nodes.size()));
  EXPECT_EQ(box.offset + box.size(), boxes.shown.node_count());
  // Every triangle within one body's part.
  for (const Triangle& tri : boxes.shown.triangles) {
    const bool in_box = tri[0] >= box.offset;
    for (int corner : tri) EXPECT_EQ(corner >= box.offset, in_box);
  }
  const view::Scene scene = view::view_scene(boxes.model, boxes.shown, wire::P1, {}, 30, "live");
  expect_view_scene_is_shown(scene, boxes.shown);
  // The page is told which shown nodes are which object's.
  ASSERT_EQ(scene.objects_size(), 2);
  EXPECT_EQ(scene.objects(0).name(), "A");
  EXPECT_EQ(scene.objects(0).model(), "mass_spring");
  EXPECT_EQ(scene.objects(0).first_node(), 0u);
  EXPECT_EQ(scene.objects(0).node_count(), static_cast<std::uint32_t>(box.offset));
  EXPECT_EQ(scene.objects(1).name(), "B");
  EXPECT_EQ(scene.objects(1).model(), "linear_elastic");
  EXPECT_EQ(scene.objects(1).first_node(), static_cast<std::uint32_t>(box.offset));
  EXPECT_EQ(scene.objects(1).node_count(), static_cast<std::uint32_t>(box.size()));
  // A's top face is at z = 26.76 + 26.56 mm: tool A's 2 mm sphere goes 2 mm into it. B's
  // displacement is its own state's (B holds A through A's backing, and is not dented by
  // A in its own state): tool B goes 1 mm into B's top face beside A.
  boxes.press({Eigen::Vector3d(0, 0, 0.05332), Eigen::Vector3d(0.035, 0.058, 0.001)}, 0.05);
  ASSERT_TRUE(boxes.simulation.pressing(0));
  ASSERT_TRUE(boxes.simulation.pressing(1));
  EXPECT_EQ(boxes.simulation.body_of(1), 1);
  const view::Frame frame = boxes.frame();
  expect_view_network_shown(frame, boxes.shown.parts[0], front);
  const Eigen::Matrix3Xd expected = behind.displacement_of(box.nodes);
  const double largest = expected.cwiseAbs().maxCoeff();
  EXPECT_GT(largest, 1e-4) << "tool B dents B";
  EXPECT_LT((frame_part_displacement(frame, box) - expected).cwiseAbs().maxCoeff(), 1e-6 * largest);
}

// The FEM pair (scenes/objects/fem_pair.yaml): tool A presses the slab A 4 mm onto the block
// B; no tool touches B, yet the view shows B dented under A (the pushes are loads in B's
// state), as B's own displacement_of says, and A as its own.
TEST(ViewBodies, TheFemPairShowsBDentedByAsPushes) {
  ViewedShippedScene pair(load_shipped_view_scene("scenes/objects/fem_pair.yaml"));
  ASSERT_EQ(pair.shown.parts.size(), 2u);
  pair.press({Eigen::Vector3d(-0.005, -0.006, 0.016)}, 0.05);
  ASSERT_TRUE(pair.simulation.pressing(0));
  ASSERT_EQ(pair.simulation.body_of(0), 0);
  const view::Frame frame = pair.frame();
  for (int body = 0; body < 2; ++body) {
    SCOPED_TRACE(body);
    const view::ShownPart& part = pair.shown.parts[static_cast<std::size_t>(body)];
    const Eigen::Matrix3Xd expected =
        std::get<Simulation>(pair.simulation.body(body)).displacement_of(part.nodes);
    const double largest = expected.cwiseAbs().maxCoeff();
    EXPECT_GT(largest,
              body == 0 ? 3e-3 : 1e-4);  // B sinks under A by a tenth of a millimetre or more
    EXPECT_LT((frame_part_displacement(frame, part) - expected).cwiseAbs().maxCoeff(),
              1e-6 * largest);
  }
}

TEST(ViewBodies, TheTissuesFrameIsItsDisplayedDent) {
  ViewedShippedScene tissue(load_shipped_view_scene("scenes/laparoscopy/tissue.yaml"));
  const auto& body = std::get<HomeSpringSimulation>(tissue.simulation.body(0));
  ASSERT_EQ(tissue.shown.node_count(), body.body().surface.vertex_count());
  EXPECT_EQ(tissue.shown.triangles, body.body().surface.triangles);
  // The probe 5 mm into the sheet near its centre.
  tissue.press({Eigen::Vector3d(0.001, 0.0005, -0.005)}, 0.002);
  ASSERT_TRUE(tissue.simulation.pressing(0));
  const view::Frame frame = tissue.frame();
  const Eigen::Matrix3Xd expected = body.displayed() - body.body().surface.vertices;
  const double largest = expected.cwiseAbs().maxCoeff();
  EXPECT_GT(largest, 1e-3);
  EXPECT_LT(
      (frame_part_displacement(frame, tissue.shown.parts[0]) - expected).cwiseAbs().maxCoeff(),
      1e-6 * largest);
  EXPECT_GT(frame.users(0).patch_nodes_size(), 0);
}

// The layers are drawn at rest; their interface goes with the scene and its separated shares
// and grooves with every frame, as the simulation holds them.
TEST(ViewBodies, TheSeparatingTissuesSceneHasBothLayersSurfacesDrawnAtRestAndItsInterface) {
  Scene scene = load_shipped_view_scene("scenes/separation/two_layers.yaml");
  std::get<SeparationObjectSpec>(scene.objects[0].body).disk_cache =
      false;  // no cache written by a test
  ViewedShippedScene layers(scene);
  const auto& body = std::get<SeparationModel>(layers.model.bodies[0]);
  const BoundarySurface pulled = extract_boundary_surface(body.bodies.pulled.mesh);
  const BoundarySurface base = extract_boundary_surface(body.bodies.base.mesh);
  const view::Scene message =
      view::view_scene(layers.model, layers.shown, wire::P1, {}, 30, "live");
  expect_view_scene_is_shown(message, layers.shown);
  ASSERT_EQ(layers.shown.node_count(), static_cast<int>(pulled.nodes.size() + base.nodes.size()));
  EXPECT_EQ(layers.shown.triangles.size(), pulled.triangles.size() + base.triangles.size());
  // The pulled layer's surface first, then the base's, each node where its mesh has it.
  for (std::size_t k = 0; k < pulled.nodes.size(); ++k)
    EXPECT_EQ(layers.shown.rest.col(static_cast<Eigen::Index>(k)),
              body.bodies.pulled.mesh.nodes.col(pulled.nodes[k]));
  for (std::size_t k = 0; k < base.nodes.size(); ++k)
    EXPECT_EQ(layers.shown.rest.col(static_cast<Eigen::Index>(pulled.nodes.size() + k)),
              body.bodies.base.mesh.nodes.col(base.nodes[k]));
  layers.press({Eigen::Vector3d(0.02, 0.02, 0.001)}, 0.01);
  const view::Frame frame = layers.frame();
  ASSERT_EQ(frame.displacement_size(), 3 * layers.shown.node_count());
  EXPECT_TRUE(std::all_of(frame.displacement().begin(), frame.displacement().end(),
                          [](float u) { return u == 0; }));
  EXPECT_TRUE(frame.users(0).present());

  const SeparationPatch& patch = *body.patch;
  ASSERT_EQ(message.interfaces_size(), 1);
  const view::Interface& face = message.interfaces(0);
  EXPECT_EQ(face.object(), 0u);
  ASSERT_EQ(face.vertices_size(), 3 * patch.node_count());
  for (int node = 0; node < patch.node_count(); ++node)
    for (int axis = 0; axis < 3; ++axis)
      EXPECT_EQ(face.vertices(3 * node + axis), static_cast<float>(patch.positions(axis, node)));
  ASSERT_EQ(face.triangles_size(), 3 * patch.triangle_count());
  for (int t = 0; t < patch.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(face.triangles(3 * t + k),
                static_cast<std::uint32_t>(patch.triangles[static_cast<std::size_t>(t)][k]));
  ASSERT_EQ(frame.interfaces_size(), 1);
  EXPECT_EQ(frame.interfaces(0).separated_area(), 0);
  EXPECT_EQ(frame.interfaces(0).groove_widths_size(), 0);

  // The fibre (user 1) fires along a 10 mm groove at 20 mm/s.
  for (int k = 0; k <= 500; ++k) {
    layers.simulation.set_tool(1, Eigen::Vector3d(0.0205, 0.015 + 2e-5 * k, 0.0002), 1u);
    layers.simulation.step(layers.time += 0.001);
  }
  const SeparationState& state = std::get<SeparationSimulation>(layers.simulation.body(0)).state();
  ASSERT_GT(state.groove.count, 0u);
  const view::Frame grooved = layers.frame();
  ASSERT_EQ(grooved.interfaces_size(), 1);
  const view::InterfaceFrame& shown = grooved.interfaces(0);
  EXPECT_EQ(shown.separated_area(), state.separated_area);
  ASSERT_EQ(shown.separated_size(), patch.triangle_count());
  for (int t = 0; t < patch.triangle_count(); ++t)
    EXPECT_EQ(shown.separated(t), static_cast<float>(state.separated[static_cast<std::size_t>(t)]));
  ASSERT_EQ(shown.groove_widths_size(), static_cast<int>(state.groove.count));
  ASSERT_EQ(shown.grooves_size(), 6 * shown.groove_widths_size());
  for (int g = 0; g < shown.groove_widths_size(); ++g) {
    const GrooveSegment& segment = state.groove.segments[static_cast<std::size_t>(g)];
    EXPECT_EQ(shown.groove_widths(g), static_cast<float>(segment.width));
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_EQ(shown.grooves(6 * g + axis), static_cast<float>(segment.a[axis]));
      EXPECT_EQ(shown.grooves(6 * g + 3 + axis), static_cast<float>(segment.b[axis]));
    }
  }
}

}  // namespace
}  // namespace cohaptic
