// The home-spring body through the IR: a HomeSpringPatch sent as the IR's body (the wire's
// HomeSpringPatch message) comes back bit for bit, and the client's evaluate_force on the
// received IR gives exactly the server's evaluate_home_spring on its own patch (client =
// server) on random pokes and pulls, grasped or not, with the IR's force limit applied; a
// lying message is refused with its problem named, before anything reads through it; the
// fuzz corpus's hand-written seeds reach the evaluation and give the closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "common/ir/evaluate_force.h"
#include "common/laparoscopy/extract_home_spring_patch.h"
#include "common/laparoscopy/home_spring_contact.h"
#include "common/util/error.h"
#include "proto/wire/ir_convert.h"
#include "support/expect_refused.h"
#include "support/ir_seed.h"
#include "support/tissue_sheet.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;
using testing::expect_refused;

HomeSpringPatch sheet_patch() {
  const TriangleSurface sheet = testing::equilateral_sheet(24, 24, 0.003);
  const VertexRings rings = vertex_rings(sheet.triangles, sheet.vertex_count());
  return extract_home_spring_patch({sheet.vertices, sheet.triangles, rings},
                                   Vector3d(0.001, -0.002, 0), 0.015, {300, 120},
                                   Vector3d(0.01, -0.02, 0.12));
}

IntermediateRepresentation envelope_of(HomeSpringPatch patch, double force_limit) {
  IntermediateRepresentation ir;
  ir.epoch = 7;
  ir.simulation_time = 1.25;
  ir.user = 1;
  ir.object = 0;
  ir.force_limit = force_limit;
  ir.body = std::move(patch);
  return ir;
}

HomeSpringPatch received(const IntermediateRepresentation& ir) {
  return std::get<HomeSpringPatch>(wire::from_wire(wire::to_wire(ir)).body);
}

void expect_same_patch(const HomeSpringPatch& a, const HomeSpringPatch& b) {
  EXPECT_TRUE(a.rest_positions == b.rest_positions);
  EXPECT_EQ(a.contact_vertex_count, b.contact_vertex_count);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.ring_offsets, b.ring_offsets);
  EXPECT_EQ(a.ring_vertices, b.ring_vertices);
  EXPECT_EQ(a.surface_vertex, b.surface_vertex);
  EXPECT_EQ(a.home_stiffness, b.home_stiffness);
  EXPECT_EQ(a.neighbour_stiffness, b.neighbour_stiffness);
  EXPECT_EQ(a.damping, b.damping);
  EXPECT_EQ(a.trocar_pivot, b.trocar_pivot);
  EXPECT_EQ(a.grasp.vertex, b.grasp.vertex);
  EXPECT_EQ(a.grasp.tool_at_grasp, b.grasp.tool_at_grasp);
}

TEST(LaparoscopyIr, WireRoundTripIsBitExact) {
  HomeSpringPatch patch = sheet_patch();
  expect_same_patch(received(envelope_of(patch, 5)), patch);
  patch.damping = 45;
  expect_same_patch(received(envelope_of(patch, 5)), patch);
  patch.grasp = {nearest_touchable_vertex(patch, Vector3d::Zero()),
                 Vector3d(0.0004, 0.0002, -0.001)};
  expect_same_patch(received(envelope_of(patch, 5)), patch);
  const IntermediateRepresentation ir = envelope_of(patch, 5);
  EXPECT_GT(ir.size_bytes(), static_cast<std::size_t>(patch.vertex_count()) * 3 * sizeof(double));
}

// The server evaluates its own patch; the client the IR it received. Same force, bit for
// bit, the limit applied on the client's side.
void expect_client_equals_server(const HomeSpringPatch& patch, unsigned seed) {
  constexpr double kLimit = 2.0;
  const PreparedHomeSpringPatch server = prepare_home_spring_patch(patch);
  const IntermediateRepresentation sent = envelope_of(patch, kLimit);
  const PreparedIR client = prepare_ir(wire::from_wire(wire::to_wire(sent)));
  EvaluationState state = make_evaluation_state(client);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> across(-0.012, 0.012), depth(-0.008, 0.006);
  int touching = 0, clamped = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Vector3d tool(across(rng), across(rng), depth(rng));
    const HomeSpringContact expected = evaluate_home_spring(server, tool);
    const ForceSample sample = evaluate_force(client, state, tool, {}, 1.0 / 2000);
    ASSERT_EQ(expected.touching, (sample.flags & kInContact) != 0) << "tool " << tool.transpose();
    if (!expected.touching) {
      EXPECT_EQ(sample.force, Vector3d::Zero());
      continue;
    }
    ++touching;
    if (expected.force.norm() > kLimit) {
      ++clamped;
      EXPECT_TRUE(sample.flags & kClamped);
      EXPECT_NEAR(sample.force.norm(), kLimit, 1e-12);
      EXPECT_NEAR(sample.force.normalized().dot(expected.force.normalized()), 1, 1e-12);
    } else {
      EXPECT_EQ(sample.force, expected.force) << "tool " << tool.transpose();
      EXPECT_EQ(sample.depth, expected.displacement.norm());
    }
  }
  EXPECT_GT(touching, 1000);
  EXPECT_GT(clamped, 10);  // the limit was exercised
}

TEST(LaparoscopyIr, ClientEvaluatesWhatTheServerWould) {
  HomeSpringPatch patch = sheet_patch();
  expect_client_equals_server(patch, 3);
  patch.grasp = {nearest_touchable_vertex(patch, Vector3d::Zero()),
                 Vector3d(0.0004, 0.0002, -0.001)};
  expect_client_equals_server(patch, 4);
}

TEST(LaparoscopyIr, NonFiniteToolGivesZeroForce) {
  const PreparedIR client = prepare_ir(envelope_of(sheet_patch(), 5));
  EvaluationState state = make_evaluation_state(client);
  const ForceSample sample =
      evaluate_force(client, state, Vector3d(0, std::nan(""), -0.001), {}, 1.0 / 2000);
  EXPECT_EQ(sample.force, Vector3d::Zero());
  EXPECT_TRUE(sample.flags & kNonFinite);
}

// The fuzz corpus's home-spring seeds (tests/fuzz/text_seeds/ir) decode and prepare, so
// fuzzing starts from IRs that reach the evaluation; the grasped one pulled straight up by
// delta gives the flat hexagon's closed form k1 delta + 6 k2 delta (1 - h / sqrt(h^2 + delta^2)).
TEST(LaparoscopyIr, FuzzSeedsReachTheEvaluation) {
  const PreparedIR free = testing::prepared_ir_seed("home_spring");
  EvaluationState free_state = make_evaluation_state(free);
  EXPECT_TRUE(evaluate_force(free, free_state, Vector3d(0.0005, 0.0003, -0.001), {}, 1e-3).flags &
              kInContact);
  const PreparedIR grasped = testing::prepared_ir_seed("home_spring_grasped");
  const HomeSpringPatch& patch = std::get<HomeSpringPatch>(grasped.ir.body);
  EvaluationState state = make_evaluation_state(grasped);
  const double h = 0.004, delta = 0.005, k1 = 300, k2 = 120;
  const ForceSample pull =
      evaluate_force(grasped, state, patch.grasp.tool_at_grasp + Vector3d(0, 0, delta), {}, 1e-3);
  EXPECT_NEAR(pull.force.z(),
              -(k1 * delta + 6 * k2 * delta * (1 - h / std::sqrt(h * h + delta * delta))), 1e-12);
  EXPECT_NEAR(pull.force.head<2>().norm(), 0, 1e-12);
}

TEST(LaparoscopyIr, LyingMessagesAreRefusedByName) {
  const wire::IntermediateRepresentation good = wire::to_wire(envelope_of(sheet_patch(), 5));
  wire::IntermediateRepresentation w = good;
  w.mutable_home_spring()->mutable_rest_positions()->RemoveLast();
  expect_refused(w, "rest_positions has");
  w = good;
  w.mutable_home_spring()->add_triangles(0);
  expect_refused(w, "not a multiple of 3");
  w = good;
  w.mutable_home_spring()->set_ring_offsets(1, 1u << 20);  // an early ring running past the list
  expect_refused(w, "ring_offsets decrease");
  w = good;
  w.mutable_home_spring()->set_ring_vertices(0, 1u << 31);
  expect_refused(w, "ring vertex = 2147483648 is out of range");
  w = good;
  w.mutable_home_spring()->mutable_grasp()->set_vertex(100000);
  expect_refused(w, "grasp names vertex 100000");
  w = good;
  w.mutable_home_spring()->set_home_stiffness(-1);
  expect_refused(w, "home_stiffness (k1) is -1");
  w = good;
  w.mutable_home_spring()->mutable_trocar_pivot()->set_x(std::nan(""));
  expect_refused(w, "trocar_pivot has a non-finite component");
}

}  // namespace
}  // namespace cohaptic
