// Compliance rows (common/ir/compliance_rows.h): a client that receives only the rows of L
// for the nodes it does not hold yet, and condenses them itself (ClientCondensation, the
// server's IncrementalCondensation), gets the server's M~ and the same forces, to 1e-9
// relative, on a generated session of two users whose tools slide across the cube (contact
// nodes join and leave every few IRs) while a held boundary set grows, shrinks and moves;
// through the wire; across a restart (reconnect) and a late join; and with B truncation (the
// IR leaves held nodes out, the client condenses over them all the same and drops their
// columns). A stale, skipped or hostile update is refused with its reason and loses
// nothing: the next right one is exact.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <memory>
#include <random>
#include <unordered_map>

#include "common/ir/build_ir.h"
#include "common/ir/client_condensation.h"
#include "common/ir/compliance_rows_sender.h"
#include "common/ir/evaluate_force.h"
#include "common/util/error.h"
#include "proto/wire/ir_convert.h"
#include "support/cube_scene.h"
#include "support/ir_seed.h"
#include "support/measures.h"

namespace cohaptic {
namespace {

using testing::mm;

// A session on the cube: per step, the users' tools on circles over the top face, and a
// held set of surface nodes away from both tools that changes every few steps.
class GeneratedSession {
 public:
  GeneratedSession(const testing::CubeRig& rig, ContactModel model, double radius,
                   double truncation = 0)
      : rig_(rig), condensation_(*rig.columns, rig.body.dofs) {
    options_.contact_model = model;
    options_.force_limit = 1000;  // compare forces, not the limit
    options_.boundary_truncation = truncation;
    radius_ = radius;
    for (std::size_t i = 0; i < rig.body.mesh.node_tags.size(); ++i)
      mesh_of_tag_.emplace(rig.body.mesh.node_tags[i], static_cast<int>(i));
  }

  /// The IRs of both users at step `step` (full M~, as the server builds them).
  std::array<IntermediateRepresentation, 2> step(int step) {
    const ElasticBody& body = rig_.body;
    const double angle = 0.31 * step;
    // Centres: a point tool 1 mm deep, a sphere's 2 mm deep.
    const Eigen::Vector3d lift(0, 0, radius_ > 0 ? radius_ - 2e-3 : 0);
    const std::array<Eigen::Vector3d, 2> tools = {
        mm(25 * std::cos(angle), 25 * std::sin(angle), -1) + lift,
        mm(-20 + 12 * std::sin(0.7 * angle), 18 * std::cos(angle), -0.5) + lift};
    std::vector<UserTool> users;
    for (int u = 0; u < 2; ++u)
      users.push_back({u, tools[u], radius_, nearest_touchable_triangle(body, tools[u]), {}});
    if (step % 4 == 0) {
      // Surface nodes at least 45 mm from both tools (none of them in a patch), a random
      // part of them: B both gains and loses nodes.
      std::vector<int> far;
      for (int node : body.surface.nodes) {
        const Eigen::Vector3d p = body.mesh.nodes.col(node);
        if (body.dofs.fixed_axes[node] != kAllAxes && (p - tools[0]).norm() > 45e-3 + radius_ &&
            (p - tools[1]).norm() > 45e-3 + radius_)
          far.push_back(node);
      }
      std::shuffle(far.begin(), far.end(), rng_);
      far.resize(std::min<std::size_t>(far.size(),
                                       std::uniform_int_distribution<std::size_t>(0, 30)(rng_)));
      condensation_.set_boundary_nodes(far);
    }
    std::vector<Eigen::Vector3d> held;
    std::uniform_real_distribution<double> uniform(-3e-4, 3e-4);
    for (std::size_t i = 0; i < condensation_.boundary_nodes().size(); ++i)
      held.emplace_back(uniform(rng_), uniform(rng_), uniform(rng_));
    tools_ = tools;
    return {build_ir(body, condensation_, users, 0, held, options_, std::uint64_t(step) + 1, 0.0),
            build_ir(body, condensation_, users, 1, held, options_, std::uint64_t(step) + 1, 0.0)};
  }

  std::vector<int> mesh_nodes(const CondensedFemIr& ir) const {
    std::vector<int> nodes;
    for (const std::int64_t tag : ir.held_node_ids()) nodes.push_back(mesh_of_tag_.at(tag));
    return nodes;
  }
  const std::array<Eigen::Vector3d, 2>& tools() const { return tools_; }

 private:
  const testing::CubeRig& rig_;
  IncrementalCondensation condensation_;
  IrBuildOptions options_;
  double radius_ = 0;
  std::unordered_map<std::int64_t, int> mesh_of_tag_;
  std::mt19937 rng_{14};
  std::array<Eigen::Vector3d, 2> tools_;
};

// `full` in the rows form, through the wire, as a client receives it.
IntermediateRepresentation as_rows(const IntermediateRepresentation& full,
                                   const std::vector<int>& mesh_nodes, ComplianceRowsSender& sender,
                                   const testing::CubeRig& rig) {
  IntermediateRepresentation rows = full;
  sender.convert(condensed_fem(rows), mesh_nodes, *rig.columns, rig.body.dofs);
  return wire::from_wire(wire::to_wire(rows));
}

double largest_entry_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

// The client's force equals the full IR's at the tool and around it (pressing deeper and
// sliding), to 1e-9 relative.
void expect_same_forces(const IntermediateRepresentation& full,
                        const IntermediateRepresentation& completed,
                        const std::array<Eigen::Vector3d, 2>& tools, int user,
                        const std::string& when) {
  const PreparedIR a = prepare_ir(full);
  const PreparedIR b = prepare_ir(completed);
  EvaluationState state_a = make_evaluation_state(a), state_b = make_evaluation_state(b);
  const std::vector<Eigen::Vector3d> remote = {tools[static_cast<std::size_t>(1 - user)]};
  int pressing = 0;
  for (const Eigen::Vector3d& offset : {mm(0, 0, 0), mm(0.5, -0.3, -0.8), mm(-0.4, 0.2, -1.5)}) {
    const Eigen::Vector3d tool = tools[static_cast<std::size_t>(user)] + offset;
    const ForceSample fa = evaluate_force(a, state_a, tool, remote, 1e-3);
    const ForceSample fb = evaluate_force(b, state_b, tool, remote, 1e-3);
    EXPECT_EQ(fa.flags, fb.flags) << when;
    EXPECT_LE((fa.force - fb.force).norm(), 1e-9 * fa.force.norm() + 1e-15)
        << when << ": " << fa.force.transpose() << " vs " << fb.force.transpose();
    pressing += fa.force.norm() > 0;
  }
  EXPECT_GT(pressing, 0) << when << ": no force to compare";
}

void run_session(ContactModel model, double radius, double truncation = 0) {
  testing::CubeSceneOptions cube;
  cube.divisions = 8;
  const testing::CubeRig rig(cube);
  GeneratedSession session(rig, model, radius, truncation);
  std::array<ComplianceRowsSender, 2> senders;
  std::array<std::unique_ptr<ClientCondensation>, 2> clients = {
      std::make_unique<ClientCondensation>(), std::make_unique<ClientCondensation>()};
  int joined = 0, left = 0;             // IRs that added nodes to a held set, or dropped some
  std::size_t kept = 0, truncated = 0;  // held nodes in the IRs and left out of them
  std::array<std::vector<std::int64_t>, 2> previous;
  for (int step = 0; step < 60; ++step) {
    if (step == 25) senders[0].restart();  // user A reconnects: the same client starts afresh
    if (step == 40) {  // user B joins late: a new client, the server from nothing
      senders[1].restart();
      clients[1] = std::make_unique<ClientCondensation>();
    }
    const std::array<IntermediateRepresentation, 2> irs = session.step(step);
    for (int user = 0; user < 2; ++user) {
      const std::string when = fmt::format("step {}, user {}", step, user);
      const CondensedFemIr& full = condensed_fem(irs[user]);
      IntermediateRepresentation received =
          as_rows(irs[user], session.mesh_nodes(full), senders[user], rig);
      const ComplianceRows& rows = *condensed_fem(received).compliance_rows;
      joined += rows.generation > 1 && rows.rows.rows() > 0;
      left += rows.generation > 1 &&
              std::any_of(previous[user].begin(), previous[user].end(), [&](std::int64_t tag) {
                return std::find(full.node_ids.begin(), full.node_ids.end(), tag) ==
                       full.node_ids.end();
              });
      previous[user] = full.node_ids;
      kept += full.node_ids.size() - static_cast<std::size_t>(full.row_node_count);
      truncated += full.truncated_node_ids.size();
      clients[user]->complete(condensed_fem(received));
      EXPECT_EQ(clients[user]->held_node_count(), full.held_node_ids().size()) << when;
      EXPECT_EQ(condensed_fem(received).node_ids, full.node_ids) << when;
      EXPECT_TRUE(condensed_fem(received).truncated_node_ids.empty()) << when;
      ASSERT_EQ(condensed_fem(received).m_tilde.rows(), full.m_tilde.rows()) << when;
      ASSERT_EQ(condensed_fem(received).m_tilde.cols(), full.m_tilde.cols()) << when;
      EXPECT_LE(largest_entry_difference(condensed_fem(received).m_tilde, full.m_tilde), 1e-12)
          << when;
      expect_same_forces(irs[user], received, session.tools(), user, when);
    }
  }
  // Not a session that never changed: nodes joined and left all along.
  EXPECT_GT(joined, 20);
  EXPECT_GT(left, 20);
  // With truncation, IRs that keep some held nodes and leave others out.
  EXPECT_GT(kept, 0u);
  EXPECT_EQ(truncated > 0, truncation > 0) << truncated << " held nodes left out";
}

TEST(ComplianceRows, ClientMTildeAndForcesEqualTheFullIrWithTranslation) {
  run_session(ContactModel::node_translation, 0);
}

TEST(ComplianceRows, ClientMTildeAndForcesEqualTheFullIrWithThePointConstraint) {
  run_session(ContactModel::point_constraint, 0);
}

// B truncation: the client's M~ (its kept columns only) and forces still equal the server's.
TEST(ComplianceRows, ClientMTildeAndForcesEqualTheTruncatedIrWithThePointConstraint) {
  run_session(ContactModel::point_constraint, 0, 0.2);
}

// `all` (every held node kept) with only the held nodes `keep` says kept, as the server
// would send it had its truncation chosen so: the others' columns of M~ and u_B left out.
IntermediateRepresentation keeping(const IntermediateRepresentation& all,
                                   const std::vector<bool>& keep) {
  IntermediateRepresentation out = all;
  const CondensedFemIr& from = condensed_fem(all);
  CondensedFemIr& to = condensed_fem(out);
  to.node_ids.resize(static_cast<std::size_t>(from.row_node_count));
  to.fixed_axes.resize(static_cast<std::size_t>(from.row_node_count));
  std::vector<Eigen::Index> columns;
  const Eigen::Index c = from.m_tilde.rows();
  for (Eigen::Index k = 0; k < c; ++k) columns.push_back(k);
  std::vector<double> displacement;
  Eigen::Index column = c;
  for (std::size_t b = 0; b < keep.size(); ++b) {
    const std::size_t node = static_cast<std::size_t>(from.row_node_count) + b;
    const int dofs = 3 - std::popcount(static_cast<unsigned>(from.fixed_axes[node]));
    if (keep[b]) {
      to.node_ids.push_back(from.node_ids[node]);
      to.fixed_axes.push_back(from.fixed_axes[node]);
      for (int k = 0; k < dofs; ++k) {
        columns.push_back(column + k);
        displacement.push_back(from.boundary_displacement(column + k - c));
      }
    } else {
      to.truncated_node_ids.push_back(from.node_ids[node]);
      to.truncated_fixed_axes.push_back(from.fixed_axes[node]);
    }
    column += dofs;
  }
  to.m_tilde = from.m_tilde(Eigen::all, columns);
  to.boundary_displacement = Eigen::Map<const Eigen::VectorXd>(
      displacement.data(), static_cast<Eigen::Index>(displacement.size()));
  return out;
}

// The client keeps the columns the server lists, whatever a threshold would choose: here the
// held nodes the truncation left out are kept, and those it kept are left out. And had the
// client condensed over the kept held nodes alone, its M_CC would differ.
TEST(ComplianceRows, TheClientKeepsTheServersChoiceAndCondensesOverEveryHeldNode) {
  testing::CubeSceneOptions cube;
  cube.divisions = 8;
  const testing::CubeRig rig(cube);
  GeneratedSession truncating(rig, ContactModel::point_constraint, 0, 0.2),
      untruncated(rig, ContactModel::point_constraint, 0);
  // The first step whose IR leaves held nodes out; both sessions draw the same states.
  IntermediateRepresentation truncated, all;
  for (int step = 0; step < 40 && condensed_fem(truncated).truncated_node_ids.empty(); ++step) {
    truncated = truncating.step(step)[0];
    all = untruncated.step(step)[0];
  }
  const CondensedFemIr& fem = condensed_fem(truncated);
  ASSERT_FALSE(fem.truncated_node_ids.empty());
  ASSERT_GT(fem.node_count(), fem.row_node_count);
  const auto completed = [&](const IntermediateRepresentation& server) {
    ComplianceRowsSender sender;
    IntermediateRepresentation ir =
        as_rows(server, truncating.mesh_nodes(condensed_fem(server)), sender, rig);
    ClientCondensation client;
    client.complete(condensed_fem(ir));
    return condensed_fem(ir).m_tilde;
  };
  EXPECT_LE(largest_entry_difference(completed(truncated), fem.m_tilde), 1e-12);
  // The server's choice, made by `keeping` from the untruncated IR: the same as build_ir's,
  // then its complement.
  std::vector<bool> keep;
  const CondensedFemIr& whole = condensed_fem(all);
  for (std::size_t i = static_cast<std::size_t>(whole.row_node_count); i < whole.node_ids.size();
       ++i)
    keep.push_back(std::find(fem.node_ids.begin(), fem.node_ids.end(), whole.node_ids[i]) !=
                   fem.node_ids.end());
  const IntermediateRepresentation same = keeping(all, keep);
  ASSERT_EQ(condensed_fem(same).node_ids, fem.node_ids);
  EXPECT_EQ(condensed_fem(same).m_tilde, fem.m_tilde);
  std::vector<bool> other = keep;
  other.flip();
  const IntermediateRepresentation reversed = keeping(all, other);
  const Eigen::MatrixXd reversed_m = completed(reversed);
  ASSERT_EQ(reversed_m.cols(), condensed_fem(reversed).m_tilde.cols());
  EXPECT_LE(largest_entry_difference(reversed_m, condensed_fem(reversed).m_tilde), 1e-12);
  // Condensing over the kept held nodes only (no truncated list): another M_CC.
  IntermediateRepresentation kept_only = truncated;
  condensed_fem(kept_only).truncated_node_ids.clear();
  condensed_fem(kept_only).truncated_fixed_axes.clear();
  const Eigen::Index c = fem.m_tilde.rows();
  EXPECT_GT(largest_entry_difference(completed(kept_only).leftCols(c), fem.m_tilde.leftCols(c)),
            1e-9);
}

TEST(ComplianceRows, RefusesStaleAndHostileRowsAndLosesNothing) {
  testing::CubeSceneOptions cube;
  cube.divisions = 6;
  const testing::CubeRig rig(cube);
  GeneratedSession session(rig, ContactModel::node_translation, 0);
  ComplianceRowsSender sender;
  std::vector<IntermediateRepresentation> full, sent;
  for (int step = 0; step < 6; ++step) {
    full.push_back(session.step(step)[0]);
    sent.push_back(
        as_rows(full.back(), session.mesh_nodes(condensed_fem(full.back())), sender, rig));
  }
  ClientCondensation client;
  const auto expect_refused = [&](IntermediateRepresentation ir, const std::string& reason) {
    try {
      client.complete(condensed_fem(ir));
      ADD_FAILURE() << "accepted: " << reason;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  };
  const auto expect_exact = [&](int i) {
    IntermediateRepresentation ir = sent[static_cast<std::size_t>(i)];
    client.complete(condensed_fem(ir));
    EXPECT_LE(largest_entry_difference(condensed_fem(ir).m_tilde,
                                       condensed_fem(full[static_cast<std::size_t>(i)]).m_tilde),
              1e-12);
  };
  expect_exact(0);
  expect_refused(sent[2], "this client holds generation 1");  // IR 1 skipped
  IntermediateRepresentation tampered = sent[1];
  condensed_fem(tampered).compliance_rows->rows(0, 0) = std::nan("");
  expect_refused(tampered, "not all finite");
  tampered = sent[1];
  Eigen::MatrixXd& rows = condensed_fem(tampered).compliance_rows->rows;
  rows.conservativeResize(rows.rows() + 1, rows.cols());
  rows.bottomRows(1).setZero();
  expect_refused(tampered, "added nodes need");
  tampered = sent[1];
  condensed_fem(tampered).node_ids.back() = condensed_fem(tampered).node_ids.front();
  expect_refused(tampered, "listed twice");
  tampered = sent[1];
  condensed_fem(tampered).compliance_rows->generation = 0;
  expect_refused(tampered, "generation 0");
  // B truncation's list of held nodes left out: one the IR also keeps, one whose rows did not
  // come (a node the client would hold without its compliance), fixed axes that do not pair.
  tampered = sent[1];
  condensed_fem(tampered).truncated_node_ids.push_back(condensed_fem(tampered).node_ids.back());
  condensed_fem(tampered).truncated_fixed_axes.push_back(condensed_fem(tampered).fixed_axes.back());
  expect_refused(tampered, "among the nodes B truncation leaves out");
  tampered = sent[1];
  condensed_fem(tampered).truncated_node_ids.push_back(std::int64_t{1} << 40);
  condensed_fem(tampered).truncated_fixed_axes.push_back(0);
  expect_refused(tampered, "added nodes need");
  tampered = sent[1];
  condensed_fem(tampered).truncated_node_ids.push_back(std::int64_t{1} << 40);
  expect_refused(tampered, "fixed axes for 1 truncated held nodes");
  EXPECT_EQ(client.generation(), 1u);
  for (int i = 1; i < 6; ++i) expect_exact(i);                // nothing was lost
  expect_refused(sent[3], "this client holds generation 6");  // a stale one
  expect_exact(0);                                            // generation 1 starts afresh
  EXPECT_THROW(prepare_ir(sent[2]), Error);  // rows never reach the evaluator uncondensed
}

TEST(ComplianceRows, TheWireRefusesRowsThatDoNotMatchTheirCount) {
  testing::CubeSceneOptions cube;
  cube.divisions = 6;
  const testing::CubeRig rig(cube);
  GeneratedSession session(rig, ContactModel::node_translation, 0);
  ComplianceRowsSender sender;
  IntermediateRepresentation ir = session.step(0)[0];
  sender.convert(condensed_fem(ir), session.mesh_nodes(condensed_fem(ir)), *rig.columns,
                 rig.body.dofs);
  wire::IntermediateRepresentation w = wire::to_wire(ir);
  ASSERT_GT(w.fem().compliance_rows_size(), 0);
  EXPECT_EQ(w.fem().m_tilde_f64_size(), 0);
  wire::IntermediateRepresentation short_rows = w;
  short_rows.mutable_fem()->mutable_compliance_rows()->RemoveLast();
  EXPECT_THROW(wire::from_wire(short_rows), Error);
  wire::IntermediateRepresentation nan_rows = w;
  nan_rows.mutable_fem()->set_compliance_rows(0, std::nan(""));
  EXPECT_THROW(wire::from_wire(nan_rows), Error);
  wire::IntermediateRepresentation both = w;
  both.mutable_fem()->add_m_tilde_f64(1.0);
  EXPECT_THROW(wire::from_wire(both), Error);
  wire::IntermediateRepresentation no_generation = w;
  no_generation.mutable_fem()->set_rows_generation(0);
  EXPECT_THROW(wire::from_wire(no_generation), Error);
  // Format 3 (rows without truncated nodes) still reads.
  wire::IntermediateRepresentation version_3 = w;
  version_3.set_format_version(3);
  EXPECT_NO_THROW(wire::from_wire(version_3));
}

TEST(ComplianceRows, TheWireCarriesTruncatedNodesWithRowsOnly) {
  testing::CubeSceneOptions cube;
  cube.divisions = 8;
  const testing::CubeRig rig(cube);
  GeneratedSession session(rig, ContactModel::point_constraint, 0, 0.2);
  IntermediateRepresentation full;  // the first step whose IR leaves held nodes out
  for (int step = 0; step < 40 && condensed_fem(full).truncated_node_ids.empty(); ++step)
    full = session.step(step)[0];
  ASSERT_FALSE(condensed_fem(full).truncated_node_ids.empty());
  // M~ whole: complete without them, so they are not sent.
  EXPECT_EQ(wire::to_wire(full).fem().truncated_node_ids_size(), 0);
  ComplianceRowsSender sender;
  IntermediateRepresentation rows = full;
  sender.convert(condensed_fem(rows), session.mesh_nodes(condensed_fem(full)), *rig.columns,
                 rig.body.dofs);
  const wire::IntermediateRepresentation w = wire::to_wire(rows);
  const IntermediateRepresentation back = wire::from_wire(w);
  EXPECT_EQ(condensed_fem(back).truncated_node_ids, condensed_fem(full).truncated_node_ids);
  EXPECT_EQ(condensed_fem(back).truncated_fixed_axes, condensed_fem(full).truncated_fixed_axes);
  EXPECT_EQ(condensed_fem(back).compliance_rows->rows, condensed_fem(rows).compliance_rows->rows);
  const auto expect_refused = [](const wire::IntermediateRepresentation& bad,
                                 const std::string& reason) {
    try {
      wire::from_wire(bad);
      ADD_FAILURE() << "accepted: " << reason;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  };
  wire::IntermediateRepresentation bad = w;
  bad.mutable_fem()->mutable_truncated_fixed_axes()->push_back('\0');
  expect_refused(bad, "truncated_fixed_axes bytes");
  bad = w;
  bad.mutable_fem()->mutable_truncated_fixed_axes()->at(0) = '\x10';
  expect_refused(bad, "not a mask");
  bad = w;
  bad.mutable_fem()->mutable_truncated_node_ids()->RemoveLast();
  bad.mutable_fem()->mutable_truncated_fixed_axes()->pop_back();
  expect_refused(bad, "compliance_rows has");
  bad = w;
  bad.set_format_version(3);
  expect_refused(bad, "cannot carry truncated held nodes");
  wire::IntermediateRepresentation m_tilde = wire::to_wire(full);
  m_tilde.mutable_fem()->add_truncated_node_ids(condensed_fem(full).truncated_node_ids.front());
  m_tilde.mutable_fem()->mutable_truncated_fixed_axes()->push_back('\0');
  expect_refused(m_tilde, "without a rows_generation");
}

// The fuzzer's seeds of an IR sent as compliance rows (the first of a recorded connection;
// a hand-written one with a truncated held node) complete and reach the evaluation, so the
// fuzzer's mutations of them do too.
TEST(ComplianceRows, TheFuzzSeedsCompleteAndPrepare) {
  for (const std::string seed : {"rows_first", "rows_truncated"}) {
    const PreparedIR prepared = testing::prepared_ir_seed(seed);
    const CondensedFemIr& fem = condensed_fem(prepared.ir);
    EXPECT_FALSE(fem.compliance_rows) << seed;
    EXPECT_TRUE(fem.truncated_node_ids.empty()) << seed;
    EXPECT_GT(fem.m_tilde.rows(), 0) << seed;
    EXPECT_EQ(fem.m_tilde.cols(),
              static_cast<Eigen::Index>(ir_dofs(fem, 0, fem.node_count()).size()))
        << seed;
  }
}

}  // namespace
}  // namespace cohaptic
