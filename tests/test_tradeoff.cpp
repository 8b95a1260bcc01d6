// The speed/accuracy trade-off: its reference (the full solve, cached per contact set)
// against the one-shot full solve, the Pareto front, and that a setting's error is
// measured against the reference it is given, not against itself.
#include <gtest/gtest.h>

#include <random>

#include "common/model/contact_reference.h"
#include "common/model/static_contact.h"
#include "common/scene/load_scene.h"
#include "common/util/error.h"
#include "lab/tradeoff.h"
#include "support/cube_scene.h"
#include "support/measures.h"

namespace cohaptic {
namespace {

using testing::mm;

Scene two_user_cube(int divisions) {
  testing::CubeSceneOptions options;
  options.divisions = divisions;
  return parse_scene(testing::cube_scene_yaml(options), "cube.yaml");
}

TEST(ContactReference, EqualsTheOneShotFullSolveAndFactorsEachContactSetOnce) {
  const Model model = build_model(two_user_cube(7));
  const ElasticBody& body = single_elastic_body(model);
  ContactReference reference(body);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> along(-12, 12), depth(0.2, 4);
  int queries = 0;
  for (int trial = 0; trial < 30; ++trial) {
    // A near (-30, 0), B near (30, 20): never on triangles sharing a node.
    const std::vector<PressedTool> tools = {
        {mm(-30 + along(rng), along(rng), -depth(rng)), 0},
        {mm(30 + along(rng), 20 + along(rng), trial % 3 == 0 ? 1.0 : -depth(rng)), 0}};
    const std::vector<Eigen::Vector3d> cached = reference.forces(tools);
    const std::vector<ToolReaction> direct = contact_reactions_reference(
        body, find_tool_contacts(body, tools), {}, ContactModel::node_translation);
    for (std::size_t u = 0; u < tools.size(); ++u)
      EXPECT_LE((cached[u] - direct[u].reaction).norm(),
                1e-9 * std::max(1e-3, direct[u].reaction.norm()))
          << "trial " << trial << " tool " << u;
    EXPECT_EQ(cached[1].isZero(), trial % 3 == 0) << "B above the face presses nothing";
    ++queries;
  }
  EXPECT_LT(reference.factorisations(), static_cast<std::size_t>(queries));
  EXPECT_GT(reference.factorisations(), 1u);
}

TEST(ContactReference, WithHeldNodesEqualsTheOneShotFullSolve) {
  const Model model = build_model(two_user_cube(7));
  const ElasticBody& body = single_elastic_body(model);
  ContactReference reference(body);
  // The front face's nodes at its left and right edges and its lower two rows, held at small
  // displacements, as an obstacle would hold them.
  HeldNodes held;
  for (int node : body.surface.nodes) {
    const Eigen::Vector3d x = body.mesh.nodes.col(node);
    if (std::abs(x.z()) < 1e-9 && (std::abs(x.x()) > 0.05 || x.y() < -0.04)) {
      held.nodes.push_back(node);
      held.displacement.emplace_back(1e-4, -2e-4,
                                     -3e-4 * static_cast<double>(held.nodes.size() % 3));
    }
  }
  ASSERT_EQ(held.nodes.size(), 28u);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> along(-8, 8), depth(0.2, 3);
  for (int trial = 0; trial < 8; ++trial) {
    const std::vector<PressedTool> tools = {{mm(-20 + along(rng), along(rng), -depth(rng)), 0},
                                            {mm(20 + along(rng), 20 + along(rng), -depth(rng)), 0}};
    const std::vector<Eigen::Vector3d> cached = reference.forces(tools, held);
    const std::vector<ToolReaction> direct = contact_reactions_reference(
        body, find_tool_contacts(body, tools), held, ContactModel::node_translation);
    for (std::size_t u = 0; u < tools.size(); ++u)
      EXPECT_LE((cached[u] - direct[u].reaction).norm(), 1e-9 * direct[u].reaction.norm())
          << "trial " << trial;
  }
  // A held node under a tool is not held: the tool wins, as in the simulation (the held
  // set may be a simulation step older than the tools).
  HeldNodes under = held;
  const std::vector<PressedTool> one = {{mm(-20, 0, -1), 0}, {mm(20, 20, 1), 0}};
  under.nodes.push_back(
      body.surface.triangles[find_tool_contacts(body, one)[0].contact->triangle][0]);
  under.displacement.emplace_back(0, 0, 1e-3);
  const Eigen::Vector3d tool_wins = reference.forces(one, under)[0];
  const Eigen::Vector3d without =
      contact_reactions_reference(body, find_tool_contacts(body, one), held,
                                  ContactModel::node_translation)[0]
          .reaction;
  EXPECT_LE((tool_wins - without).norm(), 1e-9 * without.norm());
}

TEST(Tradeoff, ParetoFrontKeepsOnlyTheUndominated) {
  //            a    b    c    d    e (= b)
  const std::vector<double> error = {1.0, 0.5, 0.8, 0.2, 0.5};
  const std::vector<double> cost = {1.0, 2.0, 2.5, 5.0, 2.0};
  const std::vector<bool> front = pareto_front(error, cost);
  EXPECT_EQ(front, (std::vector<bool>{true, true, false, true, true}));
}

TEST(Tradeoff, GridVariesOneKnobAtATimeFromTheScenesOwnSettings) {
  const Scene scene = two_user_cube(8);
  const std::vector<TradeoffSetting> grid = tradeoff_grid(scene, {6, 8, 11});
  ASSERT_FALSE(grid.empty());
  EXPECT_EQ(grid.front().name(), "baseline");
  std::map<std::string, int> per_knob;
  for (const TradeoffSetting& s : grid) {
    ++per_knob[s.knob];
    int differences = (s.divisions != 0) + (s.formulation != grid.front().formulation) +
                      (s.contact_model != grid.front().contact_model) +
                      (s.patch_rings != grid.front().patch_rings) +
                      (s.precision != grid.front().precision) +
                      (s.ir_rate_hz != grid.front().ir_rate_hz) +
                      (s.boundary_truncation != grid.front().boundary_truncation) +
                      (s.haptic_rate_hz != grid.front().haptic_rate_hz);
    EXPECT_EQ(differences, s.knob == "baseline" ? 0 : 1) << s.name();
  }
  EXPECT_EQ(per_knob["divisions"], 2) << "8 is the scene's own";
  EXPECT_EQ(per_knob["haptic_rate_hz"], 3);
  EXPECT_EQ(per_knob.count("boundary_truncation"), 0u) << "no obstacle, nothing held";
  EXPECT_EQ(single_elastic_object(scene_with(scene, grid[1])).mesh.box->divisions,
            Eigen::Vector3i(6, 6, 6));
  // A 1 kHz comparison grid leaves out the haptic rates it cannot sample.
  per_knob.clear();
  for (const TradeoffSetting& s : tradeoff_grid(scene, {}, 1000)) ++per_knob[s.knob];
  EXPECT_EQ(per_knob["haptic_rate_hz"], 1) << "500 Hz only";
  // With an obstacle, B truncation joins the grid.
  testing::CubeSceneOptions walled;
  walled.obstacles = "{name: wall, plane: {point: [0, 0, 5], normal: [0, 0, -1]}}";
  per_knob.clear();
  const std::vector<TradeoffSetting> walled_grid =
      tradeoff_grid(parse_scene(testing::cube_scene_yaml(walled), "cube.yaml"), {});
  for (const TradeoffSetting& s : walled_grid) ++per_knob[s.knob];
  EXPECT_EQ(per_knob["boundary_truncation"], 3);
  // --knob: the baseline and that knob's settings only; a knob the grid lacks is refused.
  const std::vector<TradeoffSetting> truncation = only_knobs(walled_grid, {"boundary_truncation"});
  ASSERT_EQ(truncation.size(), 4u);
  EXPECT_EQ(truncation[0].knob, "baseline");
  for (std::size_t i = 1; i < truncation.size(); ++i)
    EXPECT_EQ(truncation[i].knob, "boundary_truncation");
  EXPECT_EQ(only_knobs(walled_grid, {}).size(), walled_grid.size());
  EXPECT_THROW(only_knobs(grid, {"boundary_truncation"}), Error)
      << "no obstacle: no truncation setting";
}

TEST(Tradeoff, ErrorIsMeasuredAgainstTheReferenceNotAgainstItself) {
  const Scene scene = two_user_cube(6);
  const std::vector<Trajectory> motions = {
      Trajectory({0, 0.1, 0.3, 0.4},
                 {mm(-30, -3, 1), mm(-30, -3, -2), mm(-10, -3, -2), mm(-10, -3, 1)}, "A"),
      Trajectory({0, 0.1, 0.3, 0.4},
                 {mm(35, 30, 1), mm(35, 30, -1.5), mm(35, 30, -1.5), mm(35, 30, 1)}, "B")};
  const TradeoffSetting baseline = tradeoff_grid(scene, {}).front();
  TradeoffSetting finer = baseline;
  finer.divisions = 9;

  // Against the solve on its own mesh, the pipeline is exact but for the haptic loop's
  // hold between ticks: both error columns agree.
  const ReferenceTrace own = reference_trace(scene_with(scene, baseline), motions, 10000);
  const TradeoffRow self = run_setting(scene, baseline, motions, own);
  EXPECT_NEAR(self.error_rms, self.own_mesh_error_rms, 1e-12);
  EXPECT_LT(self.error_rms, 0.01);
  EXPECT_GT(self.error_rms, 0.0);
  EXPECT_GT(self.irs_sent, 2);

  // Against a finer mesh, the discretisation shows in the error column only.
  const ReferenceTrace fine = reference_trace(scene_with(scene, finer), motions, 10000);
  EXPECT_EQ(fine.nodes, 1000);
  const TradeoffRow coarse = run_setting(scene, baseline, motions, fine);
  EXPECT_NEAR(coarse.own_mesh_error_rms * fine.peak_force, self.own_mesh_error_rms * own.peak_force,
              1e-12);
  EXPECT_GT(coarse.error_rms, 10 * coarse.own_mesh_error_rms);
  std::printf(
      "  6-division cube: error %.2f %% against the 9-division solve, %.3f %% against its own\n",
      100 * coarse.error_rms, 100 * coarse.own_mesh_error_rms);

  // A slower haptic loop holds each force longer, so it strays further from the solve.
  TradeoffSetting slow = baseline;
  slow.haptic_rate_hz = 500;
  EXPECT_GT(run_setting(scene, slow, motions, own).own_mesh_error_rms, self.own_mesh_error_rms);

  // With a one-triangle patch, IRs at most 5 per second leave the sliding tool past its
  // patch for up to 0.2 s (force held on the rim), and fewer IRs are sent.
  TradeoffSetting small_patch = baseline;
  small_patch.patch_rings = 0;
  TradeoffSetting rare = small_patch;
  rare.ir_rate_hz = 5;
  const TradeoffRow every_change = run_setting(scene, small_patch, motions, own);
  const TradeoffRow rate_limited = run_setting(scene, rare, motions, own);
  EXPECT_GT(rate_limited.own_mesh_error_rms, 2 * every_change.own_mesh_error_rms);
  EXPECT_LT(rate_limited.irs_sent, every_change.irs_sent);
}

}  // namespace
}  // namespace cohaptic
