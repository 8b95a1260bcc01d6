// The separation patch through the IR: a SeparationIr sent as the IR's
// body (the wire's SeparationPatch, field 27) comes back bit for bit; the client's
// evaluate_force on a received IR gives the server's authoritative force for the same tool
// positions and buttons (grasp, a pull through fracture, a laser groove then a push that
// opens it), tick for tick, with the client predicting the fracture and the vaporisation
// on its own copy of the state; lying messages are refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "common/ir/evaluate_force.h"
#include "common/separation/pull_loop.h"
#include "common/sim/separation_simulation.h"
#include "common/util/error.h"
#include "proto/wire/ir_convert.h"
#include "support/ir_seed.h"
#include "support/default_two_layers.h"
#include "support/wire_round_trip.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;
using testing::default_two_layers;
using testing::over_the_wire;

std::shared_ptr<const SeparationPatch> shared_default_patch() {
  static const auto patch = std::make_shared<const SeparationPatch>(default_two_layers().patch);
  return patch;
}

// A received IR whose every part is set: some triangles separated (one partly), a laser
// tool grasping near the rim, its fibre mid-stroke.
IntermediateRepresentation busy_ir() {
  const auto patch = shared_default_patch();
  SeparationIr body;
  body.patch = patch;
  body.state = make_separation_state(*patch);
  const std::vector<int> cracked{3, 4, 40};
  separate_triangles(*patch, body.state, cracked);
  separate_in_triangle(*patch, body.state, 41, 0.3 * patch->areas[41]);
  body.tool.laser = true;
  body.tool.grasp_reach = 7e-4;
  const int node = nearest_patch_node(*patch, Vector3d(0, 0.02, 0));
  body.tool_state.contact = begin_contact(*patch, ContactMode::grasp, contact_at_node(*patch, node),
                                          patch->positions.col(node) + Vector3d(1e-4, 0, 2e-4));
  body.tool_state.fibre.firing = true;
  body.tool_state.fibre.last_tip = Vector3d(0.011, 0.017, 1e-4);
  body.tool_state.jaws_closed = true;
  IntermediateRepresentation ir;
  ir.epoch = 9;
  ir.simulation_time = 2.5;
  ir.user = 1;
  ir.object = 0;
  ir.force_limit = 3.3;
  ir.body = std::move(body);
  return ir;
}

TEST(SeparationIr, WireRoundTripIsBitExact) {
  const IntermediateRepresentation sent = busy_ir();
  const IntermediateRepresentation got = over_the_wire(sent);
  const auto& a = std::get<SeparationIr>(sent.body);
  const auto& b = std::get<SeparationIr>(got.body);
  const SeparationPatch& p = *a.patch;
  const SeparationPatch& q = *b.patch;
  EXPECT_TRUE(p.positions == q.positions);
  EXPECT_EQ(p.triangles, q.triangles);
  EXPECT_EQ(p.neighbours, q.neighbours);
  EXPECT_EQ(p.open_rim, q.open_rim);
  EXPECT_EQ(p.normals, q.normals);
  EXPECT_EQ(p.centroids, q.centroids);
  EXPECT_EQ(p.areas, q.areas);
  EXPECT_EQ(p.regions.offsets, q.regions.offsets);
  EXPECT_EQ(p.regions.triangles, q.regions.triangles);
  EXPECT_EQ(p.region_areas, q.region_areas);
  EXPECT_EQ(p.interface_area, q.interface_area);
  EXPECT_EQ(p.degree, q.degree);
  EXPECT_EQ(p.tool_node_count, q.tool_node_count);
  EXPECT_EQ(p.fields, q.fields);
  for (const auto member : {&SeparationPatch::toughness, &SeparationPatch::normal_length,
                            &SeparationPatch::tangential_length, &SeparationPatch::normal_threshold,
                            &SeparationPatch::tangential_threshold, &SeparationPatch::friction,
                            &SeparationPatch::laser_absorbed_power, &SeparationPatch::spot_diameter,
                            &SeparationPatch::laser_reach, &SeparationPatch::vaporisation_energy,
                            &SeparationPatch::vaporisation_speed, &SeparationPatch::force_limit})
    EXPECT_EQ(p.*member, q.*member);
  EXPECT_EQ(a.state.separated, b.state.separated);
  EXPECT_EQ(a.state.separated_area, b.state.separated_area);
  EXPECT_EQ(a.tool.laser, b.tool.laser);
  EXPECT_EQ(a.tool.grasp_reach, b.tool.grasp_reach);
  const SeparationContact& c = a.tool_state.contact;
  const SeparationContact& d = b.tool_state.contact;
  EXPECT_EQ(c.mode, d.mode);
  EXPECT_EQ(c.point.triangle, d.point.triangle);
  EXPECT_EQ(c.point.weights, d.point.weights);
  EXPECT_EQ(c.point.tool_nodes, d.point.tool_nodes);
  EXPECT_EQ(c.point.tool_weights, d.point.tool_weights);
  EXPECT_EQ(c.position, d.position);
  EXPECT_EQ(c.tool_offset, d.tool_offset);
  EXPECT_EQ(c.last_tool, d.last_tool);
  EXPECT_EQ(a.tool_state.fibre.firing, b.tool_state.fibre.firing);
  EXPECT_EQ(a.tool_state.fibre.last_tip, b.tool_state.fibre.last_tip);
  EXPECT_EQ(a.tool_state.jaws_closed, b.tool_state.jaws_closed);
  EXPECT_EQ(got.epoch, sent.epoch);
  EXPECT_EQ(got.force_limit, sent.force_limit);
  EXPECT_GT(sent.size_bytes(), p.fields.size() * sizeof(double));
  const std::size_t wire_bytes = wire::to_wire(sent).ByteSizeLong();
  EXPECT_NEAR(static_cast<double>(wire_bytes), static_cast<double>(sent.size_bytes()),
              0.1 * static_cast<double>(wire_bytes));
  std::printf("  the default layers' IR: %zu bytes on the wire, %zu counted by size_bytes\n",
              wire_bytes, sent.size_bytes());
}

// One user's instrument on the default layers, driven tick by tick on the server; the
// user's first IR goes over the wire and the client evaluates it on every later tick.
struct SeparationDrive {
  Vector3d tip;
  std::uint32_t buttons;
};

SeparationModel default_separation_model(const SeparationToolSettings& tool) {
  SeparationModel model;
  model.name = "layers";
  model.patch = shared_default_patch();
  model.spec.instruments.push_back({"tool", tool});
  return model;
}

struct ClientServerRun {
  int ticks = 0, in_contact = 0;
  double largest_difference = 0;  // |client - server| over the ticks [N]
  double largest_force = 0;
  double server_area = 0, client_area = 0;
  double fractured = 0, vaporised = 0;
  int pushing = 0;           // ticks the client's tool held a push contact
  double furthest_slip = 0;  // the furthest c went from where a contact began [m]
};

template <typename Script>
ClientServerRun run_client_and_server(const SeparationToolSettings& tool, int ticks,
                                      const Script& script) {
  const SeparationModel model = default_separation_model(tool);
  SeparationSimulation server(model, 0, {ToolSpec{"tool", ToolShape::point, 0, {}}}, 3.3);
  const double dt = 1e-3;
  SeparationDrive first = script(0);
  server.set_tool(0, first.tip, first.buttons);
  server.step(0);
  const PreparedIR client_ir = prepare_ir(over_the_wire(server.ir(0)->ir));
  EvaluationState client = make_evaluation_state(client_ir);
  ClientServerRun run;
  bool touching = false;
  Vector3d began = Vector3d::Zero();  // c when the client's contact began
  for (int i = 1; i <= ticks; ++i) {
    const SeparationDrive drive = script(i);
    server.set_tool(0, drive.tip, drive.buttons);
    server.step(i * dt);
    const ForceSample expected = server.force(0);
    const ForceSample got = evaluate_force(client_ir, client, drive.tip, {}, dt, drive.buttons);
    run.largest_difference = std::max(run.largest_difference, (got.force - expected.force).norm());
    run.largest_force = std::max(run.largest_force, expected.force.norm());
    EXPECT_EQ(got.flags, expected.flags) << "tick " << i;
    run.in_contact += (expected.flags & kInContact) ? 1 : 0;
    const SeparationContact& contact = std::get<SeparationEvaluation>(client.body).tool.contact;
    if (contact.mode != ContactMode::none && !touching) began = contact.position;
    touching = contact.mode != ContactMode::none;
    if (touching) {
      run.furthest_slip = std::max(run.furthest_slip, (contact.position - began).norm());
      run.pushing += contact.mode == ContactMode::push;
    }
    ++run.ticks;
  }
  run.server_area = server.state().separated_area;
  run.client_area = std::get<SeparationEvaluation>(client.body).state.separated_area;
  run.fractured = server.fractured_area();
  run.vaporised = server.vaporised_area();
  return run;
}

TEST(SeparationIr, ClientForceEqualsTheServersThroughAPullThatTears) {
  // Forceps close on the flap's free rim and pull it straight up at 10 mm/s for 8 mm: the
  // paper's Fig. 10 loading and fracture phases (F_n is reached near 6 mm), then back down.
  const Vector3d rim = default_two_layers().patch.positions.col(
      nearest_patch_node(default_two_layers().patch, Vector3d(0, 0.02, 0)));
  const ClientServerRun run = run_client_and_server({}, 1600, [&](int i) {
    const double up = i <= 800 ? 1e-5 * i : 1e-5 * (1600 - i);
    return SeparationDrive{rim + Vector3d(0, 0, up), i >= 5 ? 1u : 0u};
  });
  EXPECT_GT(run.fractured, 0) << "the pull did not tear; peak " << run.largest_force << " N, area "
                              << run.server_area;
  EXPECT_GT(run.in_contact, 1400);
  EXPECT_GT(run.largest_force, 0.9 * default_two_layers().patch.normal_threshold);
  EXPECT_LE(run.largest_difference, 1e-9 * run.largest_force);
  EXPECT_EQ(run.client_area, run.server_area) << "the client predicted the same fracture";
  RecordProperty("largest_difference_N", std::to_string(run.largest_difference));
}

TEST(SeparationIr, ClientForceEqualsTheServersThroughALaserGrooveAndAPushThatOpensIt) {
  // A laser tool: the fibre cuts a groove across the middle at half v_s (button 0), then
  // its jaws close on the node 0.5 mm before the groove (button 1) and push along x into it.
  const SeparationPatch& patch = default_two_layers().patch;
  const double speed = 0.5 * patch.vaporisation_speed, dt = 1e-3;
  const Vector3d from(0.0205, 0.012, 0), to(0.0205, 0.028, 0);
  const int cut = static_cast<int>(std::ceil((to - from).norm() / (speed * dt)));
  const Vector3d grip(0.02, 0.02, 0);
  const ClientServerRun run = run_client_and_server({.laser = true}, cut + 400, [&](int i) {
    if (i <= cut) return SeparationDrive{from + (to - from) * (double(i) / cut), 1u};
    const int k = i - cut;
    if (k <= 50) return SeparationDrive{to + (grip - to) * (k / 50.0), 0u};  // laser off, jaws open
    return SeparationDrive{grip + Vector3d(2e-5 * (k - 50), 0, 0),
                           2u};  // jaws closed, pushing along x
  });
  EXPECT_GT(run.vaporised, 0.9 * patch.spot_diameter * (to - from).norm()) << "no groove";
  EXPECT_GT(run.fractured, 0) << "the push did not open the groove";
  EXPECT_LE(run.largest_difference, 1e-9 * run.largest_force);
  EXPECT_EQ(run.client_area, run.server_area);
}

TEST(SeparationIr, ClientForceEqualsTheServersThroughAPushingToolThatSlidesToTheGrooveAndOpensIt) {
  // A blunt laser tool (contact: push): the fibre cuts the groove, goes down out of reach and
  // over to 1.5 mm before the groove, comes up under the flap (it touches 1 mm below the
  // interface), presses it up by 1 mm and drags it along x: c slides by friction to the
  // groove's edge and stops there, and the push tears the interface on from it.
  const SeparationPatch& patch = default_two_layers().patch;
  const double speed = 0.5 * patch.vaporisation_speed, dt = 1e-3;
  const Vector3d from(0.0205, 0.012, 0), to(0.0205, 0.028, 0), below(0, 0, -0.002);
  const int cut = static_cast<int>(std::ceil((to - from).norm() / (speed * dt)));
  const Vector3d start(0.019, 0.0203, 0);
  const auto along = [](const Vector3d& a, const Vector3d& b, int k, int of) {
    return a + (b - a) * (static_cast<double>(k) / of);
  };
  const ClientServerRun run =
      run_client_and_server({.laser = true, .contact = ContactMode::push}, cut + 1000, [&](int i) {
        if (i <= cut) return SeparationDrive{along(from, to, i, cut), 1u};
        const int k = i - cut;
        if (k <= 50) return SeparationDrive{along(to, to + below, k, 50), 1u};  // firing: off it
        if (k <= 150) return SeparationDrive{along(to + below, start + below, k - 50, 100), 0u};
        if (k <= 350)  // up under the flap: touches at 1 mm below, presses 1 mm up
          return SeparationDrive{along(start + below, start + Vector3d(0, 0, 1e-3), k - 150, 200),
                                 0u};
        return SeparationDrive{start + Vector3d(2e-5 * (k - 350), 0, 1e-3), 0u};  // drag along x
      });
  EXPECT_GT(run.vaporised, 0.9 * patch.spot_diameter * (to - from).norm()) << "no groove";
  EXPECT_GT(run.in_contact, 500);
  EXPECT_EQ(run.pushing, run.in_contact) << "the tool pushes, it never grasps";
  // c slid from x = 19 mm to the crack edge the groove opened (the cell edge x = 20 mm).
  EXPECT_GE(run.furthest_slip, 0.9e-3);
  EXPECT_GT(run.fractured, 0) << "the push did not open the groove";
  EXPECT_LE(run.largest_difference, 1e-9 * run.largest_force);
  EXPECT_EQ(run.client_area, run.server_area);
}

// The fuzz corpus's hand-written seeds (tests/fuzz/text_seeds/ir/separation*.txtpb) are
// accepted and reach the evaluation: the grasped one, pulled 0.1 mm along the normal, gives
// Eq. 2 blended by hand over its areas (fields k_z = 300, 150, 60 N/m; triangle 0 half
// separated: A(R-bar) = 1/4, 1/2, 1/4 at its nodes, A(S-bar) = 1/4; c at weights 1/2, 1/4, 1/4).
TEST(SeparationIr, FuzzSeedsReachTheEvaluation) {
  const PreparedIR free = testing::prepared_ir_seed("separation");
  EvaluationState free_state = make_evaluation_state(free);
  EXPECT_EQ(evaluate_force(free, free_state, Vector3d(0.002, 0.001, 0.0001), {}, 1e-3, 0).force,
            Vector3d::Zero());
  const PreparedIR grasped = testing::prepared_ir_seed("separation_grasped");
  EvaluationState state = make_evaluation_state(grasped);
  const auto field = [](double local, double global) {
    return (1 - global) * ((1 - local) * 300 + local * 150) + global * 60;
  };
  const double k = 0.5 * field(0.25, 0.25) + 0.25 * field(0.5, 0.25) + 0.25 * field(0.25, 0.25);
  const ForceSample pull =
      evaluate_force(grasped, state, Vector3d(0.002, 0.001, 0.0003), {}, 1e-3, 1);
  EXPECT_TRUE(pull.flags & kInContact);
  EXPECT_NEAR(pull.force.z(), -k * 1e-4, 1e-15);
  EXPECT_NEAR(pull.force.head<2>().norm(), 0, 1e-15);
  // Jaws open: it lets go.
  EXPECT_EQ(evaluate_force(grasped, state, Vector3d(0.002, 0.001, 0.0003), {}, 1e-3, 0).force,
            Vector3d::Zero());
}

void expect_separation_refused(const wire::IntermediateRepresentation& message,
                               const std::string& fragment) {
  try {
    wire::from_wire(message);
    ADD_FAILURE() << "accepted; expected an error containing \"" << fragment << "\"";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(SeparationIr, LyingMessagesAreRefusedByName) {
  const wire::IntermediateRepresentation good = wire::to_wire(busy_ir());
  wire::IntermediateRepresentation w = good;
  w.mutable_separation()->set_triangles(4, 100000);
  expect_separation_refused(w, "triangle 1 names node 100000");
  w = good;
  w.mutable_separation()->set_neighbours(0, 5000);
  expect_separation_refused(w, "names neighbour 5000");
  w = good;
  w.mutable_separation()->set_region_offsets(1, 30);
  expect_separation_refused(w, "a region of 30 triangles");
  w = good;
  w.mutable_separation()->mutable_fields()->RemoveLast();
  expect_separation_refused(w, "field values, expected");
  w = good;
  w.mutable_separation()->set_fields(7, std::nan(""));
  expect_separation_refused(w, "field value 7 is not finite");
  w = good;
  w.mutable_separation()->set_separated(3, 1.5);
  expect_separation_refused(w, "separated share 1.5");
  w = good;
  w.mutable_separation()->mutable_contact()->set_mode(7);
  expect_separation_refused(w, "contact mode 7");
  w = good;
  w.mutable_separation()->mutable_contact()->set_triangle(1u << 31);
  expect_separation_refused(w, "contact triangle = 2147483648 is out of range");
  w = good;
  w.mutable_separation()->set_tool_contact(3);
  expect_separation_refused(w, "tool_contact 3 is neither grasp (1) nor push (2)");
  w = good;
  w.mutable_separation()->set_tool_contact(257);
  expect_separation_refused(w, "tool_contact 257");
  w = good;
  w.mutable_separation()->set_toughness(-75);
  expect_separation_refused(w, "toughness (J_c) must be a positive finite number");
  w = good;
  w.mutable_separation()->set_open_rim(std::string(w.separation().open_rim().size(), '\x09'));
  expect_separation_refused(w, "crack flags 9");
}

}  // namespace
}  // namespace cohaptic
