// The trade-off's home-spring row beside its FEM twin: its error is measured against the
// reference it is given (the FEM twin's full solve, or the home-spring model's own answer
// at every sample), while its own-model column is the IR pipeline's alone.
#include <gtest/gtest.h>

#include "common/model/model.h"
#include "common/scene/load_scene.h"
#include "common/sim/home_spring_simulation.h"
#include "lab/tradeoff.h"
#include "lab/tradeoff_home_spring.h"
#include "support/measures.h"

namespace cohaptic {
namespace {

using testing::mm;

const std::filesystem::path kLaparoscopy =
    std::filesystem::path(COHAPTIC_SOURCE_DIR) / "scenes/laparoscopy";

TEST(LaparoscopyTradeoff, HomeSpringRowIsMeasuredAgainstTheReferenceItIsGiven) {
  // The shipped tissue without its dashpot: a dashpot's force steps with the velocity at
  // each corner of the motion below, and the haptic loop's hold between ticks would turn
  // those steps into an own-model error far above the elastic tissue's bound here.
  Scene tissue = load_scene(kLaparoscopy / "tissue.yaml");
  std::get<HomeSpringObjectSpec>(tissue.objects.front().body).damping = 0;
  const Scene fem = load_scene(kLaparoscopy / "tissue_fem.yaml");
  // Press, slide across a few vertices, release; the second tool pokes beside it.
  const std::vector<Trajectory> motions = {
      Trajectory({0, 0.1, 0.3, 0.4}, {mm(-10, 5, 1), mm(-10, 5, -4), mm(-2, 5, -4), mm(-2, 5, 1)},
                 "probe"),
      Trajectory({0, 0.1, 0.3, 0.4}, {mm(10, -5, 1), mm(10, -5, -3), mm(10, 1, -3), mm(10, 1, 1)},
                 "forceps")};
  constexpr double kSampleRate = 10000;
  const ReferenceTrace twin = reference_trace(fem, motions, kSampleRate);
  const TradeoffRow row = run_home_spring_setting(tissue, motions, twin, 10, 10);
  EXPECT_EQ(row.nodes, 441);
  EXPECT_GT(row.irs_sent, 4) << "the sliding tools' contact vertices changed";
  EXPECT_GT(row.own_mesh_error_rms, 0) << "the haptic loop holds each force for a tick";
  EXPECT_LT(row.own_mesh_error_rms, 0.01);
  EXPECT_GT(row.error_rms, 10 * row.own_mesh_error_rms) << "the two models differ";

  // The home-spring model's own answer at every sample as the reference: then both columns
  // are the same errors over the same peak.
  ReferenceTrace own = twin;
  const Model model = build_model(tissue);
  HomeSpringSimulation exact(std::get<HomeSpringBody>(model.bodies.front()), 0, tissue.tools,
                             std::numeric_limits<double>::infinity());
  own.peak_force = 0;
  for (std::size_t j = 0; j < own.positions.size(); ++j) {
    for (int u = 0; u < 2; ++u) exact.set_tool(u, own.positions[j][static_cast<std::size_t>(u)]);
    exact.step(static_cast<double>(j) / kSampleRate);
    for (int u = 0; u < 2; ++u) {
      own.forces[j][static_cast<std::size_t>(u)] = exact.force(u).force;
      own.peak_force = std::max(own.peak_force, own.forces[j][static_cast<std::size_t>(u)].norm());
    }
  }
  const TradeoffRow self = run_home_spring_setting(tissue, motions, own, 10, 10);
  EXPECT_NEAR(self.error_rms, self.own_mesh_error_rms, 1e-12);
  EXPECT_NEAR(self.own_mesh_error_rms * own.peak_force, row.own_mesh_error_rms * twin.peak_force,
              1e-12);
  std::printf(
      "  home springs against the FEM twin: error %.1f %% (own model %.3f %%), peak %.3f N against "
      "%.3f N\n",
      100 * row.error_rms, 100 * row.own_mesh_error_rms, own.peak_force, twin.peak_force);
}

}  // namespace
}  // namespace cohaptic
