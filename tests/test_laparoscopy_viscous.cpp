// The viscous home spring (common/laparoscopy/viscous_home_spring.h), the laparoscopy
// paper's viscous element, against independent answers:
//   - a vertex let go of returns home as the closed form u(0) exp(-t k / c), k the home spring
//     (normal to a flat ring) or k1 + 3 k2 (in its plane, the ring's linear stiffness), the
//     integrator's error first order in dt;
//   - a probe pressed at constant speed feels k1 d + c v, drawn back slowly k1 d - c v, and
//     drawn back faster than the vertex returns it lets go and feels nothing until it reaches
//     the vertex again;
//   - without damping the contact is the elastic one, bit for bit;
//   - on the server, the dent a probe leaves relaxes as the closed form while its P0 force is
//     zero, and goes on across a new IR; the scene key loads and is checked.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/ir/evaluate_force.h"
#include "common/laparoscopy/home_spring_force.h"
#include "common/laparoscopy/vertex_rings.h"
#include "common/laparoscopy/viscous_home_spring.h"
#include "common/model/model.h"
#include "common/scene/load_scene.h"
#include "common/sim/home_spring_simulation.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;

constexpr double kViscousHome = 300;    // k1 [N/m]
constexpr double kViscousDamping = 60;  // c [N s/m]: a time constant c / k1 of 0.2 s
constexpr double kRingRadius = 0.004;   // the ring's radius [m]

// A flat regular hexagon in z = 0, vertex 0 at its centre, every vertex touchable, the
// trocar 0.1 m straight above the centre.
HomeSpringPatch viscous_hexagon(double neighbour_stiffness, double damping) {
  HomeSpringPatch patch;
  patch.rest_positions.resize(3, 7);
  patch.rest_positions.col(0).setZero();
  for (int j = 0; j < 6; ++j) {
    const double angle = j * std::acos(-1.0) / 3;
    patch.rest_positions.col(j + 1) =
        Vector3d(kRingRadius * std::cos(angle), kRingRadius * std::sin(angle), 0);
  }
  patch.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}, {0, 5, 6}, {0, 6, 1}};
  const VertexRings rings = vertex_rings(patch.triangles, 7);
  patch.contact_vertex_count = 7;
  patch.ring_offsets = rings.offsets;
  patch.ring_vertices = rings.vertices;
  patch.surface_vertex = {10, 11, 12, 13, 14, 15, 16};
  patch.home_stiffness = kViscousHome;
  patch.neighbour_stiffness = neighbour_stiffness;
  patch.damping = damping;
  patch.trocar_pivot = Vector3d(0, 0, 0.1);
  return patch;
}

// The largest distance, over [0, duration], between the vertex relaxed from `start` in steps
// of `dt` and start exp(-t stiffness / c).
double largest_error_from_exponential(const HomeSpringPatch& patch, const Vector3d& start,
                                      double stiffness, double dt, double duration) {
  Vector3d u = start;
  double largest = 0;
  const int steps = static_cast<int>(std::lround(duration / dt));
  for (int n = 1; n <= steps; ++n) {
    u = relax_home_spring_vertex(patch, 0, u, dt);
    const Vector3d exact = start * std::exp(-n * dt * stiffness / patch.damping);
    largest = std::max(largest, (u - exact).norm());
  }
  return largest;
}

TEST(ViscousHomeSpring, AVertexLetGoReturnsHomeAsTheClosedFormToFirstOrderInDt) {
  const double tau = kViscousDamping / kViscousHome;
  // Normal to the flat ring, only the home spring holds the vertex (k2 = 0: exactly linear).
  const HomeSpringPatch home_only = viscous_hexagon(0, kViscousDamping);
  const Vector3d pressed(0, 0, -0.003);
  const double coarse =
      largest_error_from_exponential(home_only, pressed, kViscousHome, 1e-3, 3 * tau);
  const double fine =
      largest_error_from_exponential(home_only, pressed, kViscousHome, 2.5e-4, 3 * tau);
  // Implicit Euler's error peaks at t = tau near |u0| h / (2e), h = dt / tau.
  EXPECT_LT(coarse, 0.002 * pressed.norm());
  EXPECT_GT(coarse, 0.0005 * pressed.norm()) << "a first-order method has an error this large";
  EXPECT_NEAR(coarse / fine, 4, 0.2) << "first order: a quarter of the step, a quarter the error";

  // In the ring's plane, a small displacement feels k1 + 3 k2 (each spring k2 cos^2).
  const double neighbour = 120;
  const HomeSpringPatch ring = viscous_hexagon(neighbour, kViscousDamping);
  const Vector3d sideways(1e-5, 0, 0);
  const double in_plane = kViscousHome + 3 * neighbour;
  EXPECT_LT(largest_error_from_exponential(ring, sideways, in_plane, 2.5e-4, 3 * tau),
            0.001 * sideways.norm());
  // Far out (3 mm on a 4 mm ring) the springs are not linear, but the vertex still goes home.
  Vector3d u(0.002, -0.001, -0.003);
  for (int n = 0; n < 4000; ++n) u = relax_home_spring_vertex(ring, 0, u, 1e-3);
  EXPECT_LT(u.norm(), 1e-9);
}

// A probe on the hexagon's centre line, `depth` below the rest surface, evaluated over `dt`.
HomeSpringContact probe_on_axis(const PreparedHomeSpringPatch& prepared, MovingVertex& moving,
                                double depth, double dt, double sideways = 0) {
  return evaluate_viscous_home_spring(prepared, moving, Vector3d(sideways, 0, -depth), dt);
}

TEST(ViscousHomeSpring, AProbeFeelsSpringPlusDashpotAndLetsGoWhenDrawnBackFasterThanItReturns) {
  const PreparedHomeSpringPatch prepared =
      prepare_home_spring_patch(viscous_hexagon(0, kViscousDamping));
  constexpr double kDt = 1e-3;
  MovingVertex moving;

  // Pressed in at 20 mm/s to 3 mm: k1 d + c v, the first tick (taking hold) without c v.
  const double speed = 0.02;
  for (int n = 1; n <= 150; ++n) {
    const double depth = speed * n * kDt;
    const HomeSpringContact contact = probe_on_axis(prepared, moving, depth, kDt);
    ASSERT_TRUE(contact.touching);
    const double expected = kViscousHome * depth + (n > 1 ? kViscousDamping * speed : 0);
    EXPECT_NEAR(contact.force.z(), expected, 1e-9 * expected) << "tick " << n;
    EXPECT_NEAR(contact.force.head<2>().norm(), 0, 1e-12);
  }
  ASSERT_TRUE(moving.held);

  // Drawn back at 1 mm/s, slower than the vertex would return (k1 d / c = 15 mm/s): it
  // follows the tool, which feels k1 d - c v.
  double depth = 0.003;
  const double slow = 0.001;
  for (int n = 0; n < 100; ++n) {
    depth -= slow * kDt;
    const HomeSpringContact contact = probe_on_axis(prepared, moving, depth, kDt);
    ASSERT_TRUE(contact.touching) << "tick " << n;
    const double expected = kViscousHome * depth - kViscousDamping * slow;
    EXPECT_NEAR(contact.force.z(), expected, 1e-9 * expected) << "tick " << n;
  }

  // Drawn back at 50 mm/s, faster than that: the tool lets go at once and feels nothing, the
  // vertex returns on its own as the closed form.
  const double let_go_at = depth;
  const double fast = 0.05;
  int ticks = 0;
  for (; ticks < 50; ++ticks) {
    depth -= fast * kDt;
    const HomeSpringContact contact = probe_on_axis(prepared, moving, std::max(depth, -0.01), kDt);
    EXPECT_FALSE(contact.touching) << "tick " << ticks;
    EXPECT_EQ(contact.force, Vector3d::Zero());
    ASSERT_EQ(moving.vertex, 0);
    EXPECT_FALSE(moving.held);
    const double exact = let_go_at * std::exp(-(ticks + 1) * kDt * kViscousHome / kViscousDamping);
    EXPECT_NEAR(-moving.displacement.z(), exact, 0.002 * let_go_at) << "tick " << ticks;
  }

  // Pressed in again, it touches nothing until it reaches the vertex on its way home, then
  // holds it (the elastic force on the tick it takes hold).
  const double vertex_depth = -moving.displacement.z();
  ASSERT_GT(vertex_depth, 0.0015);
  EXPECT_FALSE(probe_on_axis(prepared, moving, 0.5 * vertex_depth, kDt).touching);
  const double below = -moving.displacement.z() + 1e-4;  // past where it has relaxed to now
  const HomeSpringContact reached = probe_on_axis(prepared, moving, below, kDt);
  ASSERT_TRUE(reached.touching);
  EXPECT_NEAR(reached.force.z(), kViscousHome * below, 1e-9 * kViscousHome * below);
  EXPECT_TRUE(moving.held);

  // Out of the tissue altogether, the vertex goes home and is forgotten there.
  for (int n = 0; n < 5000 && moving.vertex >= 0; ++n)
    EXPECT_FALSE(probe_on_axis(prepared, moving, -0.01, kDt).touching);
  EXPECT_EQ(moving.vertex, -1);
}

TEST(ViscousHomeSpring, ForcepsHoldTheVertexBothWaysAgainstSpringAndDashpot) {
  HomeSpringPatch patch = viscous_hexagon(0, kViscousDamping);
  patch.grasp = {0, Vector3d(0, 0, 0)};
  const PreparedHomeSpringPatch prepared = prepare_home_spring_patch(patch);
  // The jaws close on a vertex the probe end had pushed 3 mm in: u is measured anew from the
  // grasp, and the grasp's first tick has no dashpot term (not c (0 - 3 mm) / dt).
  MovingVertex moving{0, 10, true, false, Vector3d::Zero(), Vector3d(0, 0, -0.003)};
  constexpr double kDt = 1e-3;
  EXPECT_EQ(evaluate_viscous_home_spring(prepared, moving, Vector3d::Zero(), kDt).force,
            Vector3d::Zero());
  const double speed = 0.05;  // pulled up, far faster than the vertex could follow alone
  for (int n = 1; n <= 60; ++n) {
    const HomeSpringContact contact =
        evaluate_viscous_home_spring(prepared, moving, Vector3d(0, 0, speed * n * kDt), kDt);
    ASSERT_TRUE(contact.touching);
    const double expected = -(kViscousHome * speed * n * kDt + kViscousDamping * speed);
    EXPECT_NEAR(contact.force.z(), expected, 1e-9 * std::abs(expected)) << "tick " << n;
  }
}

TEST(ViscousHomeSpring, WithoutDampingItIsTheElasticContactBitForBit) {
  const PreparedHomeSpringPatch prepared = prepare_home_spring_patch(viscous_hexagon(120, 0));
  MovingVertex moving;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> across(-0.004, 0.004), depth(-0.003, 0.006);
  int touching = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Vector3d tool(across(rng), across(rng), -depth(rng));
    const HomeSpringContact elastic = evaluate_home_spring(prepared, tool);
    const HomeSpringContact viscous = evaluate_viscous_home_spring(prepared, moving, tool, 1e-3);
    ASSERT_EQ(viscous.touching, elastic.touching);
    EXPECT_EQ(viscous.force, elastic.force);
    EXPECT_EQ(viscous.vertex, elastic.vertex);
    EXPECT_EQ(moving.held, elastic.touching);
    touching += elastic.touching;
  }
  EXPECT_GT(touching, 500);
}

TEST(ViscousHomeSpring, TheMovingVertexGoesOnToAnotherPatchBySurfaceIndex) {
  HomeSpringPatch to = viscous_hexagon(0, kViscousDamping);
  to.surface_vertex = {13, 14, 15, 16, 10, 11, 12};  // surface vertex 10 is 4 of `to`
  MovingVertex moving{0, 10, false, false, Vector3d::Zero(), Vector3d(0, 0, -0.001)};
  carry_moving_vertex(to, moving);
  EXPECT_EQ(moving.vertex, 4);
  EXPECT_EQ(moving.displacement, Vector3d(0, 0, -0.001));
  to.surface_vertex = {20, 21, 22, 23, 24, 25, 26};
  carry_moving_vertex(to, moving);
  EXPECT_EQ(moving.vertex, -1) << "not on the new patch: at rest";
}

// An 80 x 80 mm sheet at z = 0 in 4 mm cells, k2 = 0, a probe straight above the centre.
const std::string kViscousTissue = R"(name: viscous-tissue
units: mm
objects:
  - name: tissue
    model: home_spring
    surface: {grid: {min: [-40, -40, 0], size: [80, 80], divisions: [20, 20]}}
    stiffness: {home: 300, neighbour: 0}
    damping: 60
    patch_radius: 12
    display: {deformation: polynomial, radius: 20}
tools:
  - {name: probe, shape: probe, trocar: [0, 0, 120]}
haptic: {rate_hz: 1000, force_limit: 100}
)";

TEST(ViscousHomeSpring, TheServersDentRelaxesAsTheClosedFormAfterTheProbeLeaves) {
  const Model model = build_model(parse_scene(kViscousTissue, "tissue.yaml"));
  const auto& body = std::get<HomeSpringBody>(model.bodies[0]);
  EXPECT_EQ(body.spec.damping, 60);
  HomeSpringSimulation simulation(body, 0, model.scene.tools, 100);
  constexpr double kStep = 0.002;  // the server's period [s]
  double time = 0;
  const double depth = 0.004;
  for (int n = 0; n <= 100; ++n, time += kStep) {  // held 4 mm in for 0.2 s
    simulation.set_tool(0, Vector3d(0, 0, -depth));
    simulation.step(time);
  }
  ASSERT_TRUE(simulation.pressing(0));
  EXPECT_NEAR(simulation.force(0).force.z(), kViscousHome * depth, 1e-9);
  ASSERT_EQ(simulation.dents().size(), 1u);
  EXPECT_EQ(simulation.dents()[0].to, Vector3d(0, 0, -depth));

  // Withdrawn above the tissue, then moved aside to another vertex's patch (a new IR): the
  // tool feels nothing, the dent returns as exp(-t k1 / c).
  const double left_at = time - kStep;
  int patches = 0;
  std::uint64_t epoch = simulation.ir(0)->ir.epoch;
  for (int n = 0; n < 200; ++n, time += kStep) {
    simulation.set_tool(0, Vector3d(n < 100 ? 0 : 0.002, 0, 0.01));
    simulation.step(time);
    EXPECT_FALSE(simulation.pressing(0));
    EXPECT_EQ(simulation.force(0).force, Vector3d::Zero());
    if (simulation.ir(0)->ir.epoch != epoch) ++patches;
    epoch = simulation.ir(0)->ir.epoch;
    const std::vector<TissueDent> dents = simulation.dents();
    ASSERT_EQ(dents.size(), 1u) << "step " << n;
    EXPECT_LT((dents[0].from - Vector3d::Zero()).norm(), 1e-12);
    const double exact = depth * std::exp(-(time - left_at) * kViscousHome / kViscousDamping);
    EXPECT_NEAR(-(dents[0].to - dents[0].from).z(), exact, 0.005 * depth) << "step " << n;
  }
  EXPECT_EQ(patches, 1) << "the probe aimed at another vertex once";
  EXPECT_GT(simulation.displayed().col(0).norm(), 0);

  // A negative damping is refused by name.
  try {
    parse_scene(
        std::string(kViscousTissue).replace(kViscousTissue.find("damping: 60"), 11, "damping: -1"),
        "tissue.yaml");
    ADD_FAILURE() << "a negative damping loaded";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("tissue.yaml:8: objects[0].damping"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace cohaptic
