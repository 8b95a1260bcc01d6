// Fracture at the separating interface: the paper's
// Fig. 10 normal pull with its three phases, the energy balance at other speeds and angles,
// the tangential threshold, and that no crack means no fracture until a laser groove.
// The answers they are checked against: the fitted fields themselves (AB, CA), the
// thresholds J_c l from the paper's energy balance, the work the hand does (integrated
// from the forces) against J_c times the separated area, and passivity.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "common/separation/laser_groove.h"
#include "common/separation/fracture_step.h"
#include "common/separation/pull_loop_figure.h"
#include "common/separation/separation_setup.h"
#include "support/default_two_layers.h"

namespace cohaptic {
namespace {

using testing::default_two_layers;

// On the default layers the interface has J_c = 75 J/m^2, l_n = 12 mm and l_t = 6 mm.
int rim_node() {
  return nearest_patch_node(default_two_layers().patch, Eigen::Vector3d(0, 0.02, 0));
}
int centre_node() {
  return nearest_patch_node(default_two_layers().patch, Eigen::Vector3d(0.02, 0.02, 0));
}

TEST(SeparationFracture, ThePlateauReachSaysWhereLnHoldsThePullAndNamesTheBound) {
  SeparationPatch patch = default_two_layers().patch;
  // The default l_n holds everywhere, and nothing is said.
  const PlateauReach everywhere = plateau_reach(patch);
  EXPECT_EQ(everywhere.nodes, patch.node_count());
  EXPECT_EQ(everywhere.held, everywhere.nodes);
  EXPECT_EQ(plateau_warning(everywhere, patch.normal_length), "");
  // Half of it holds at the rim but not at the centre (docs/separation.md).
  patch.normal_length *= 0.5;
  const PlateauReach reach = plateau_reach(patch);
  EXPECT_GT(reach.held, 0);
  EXPECT_LT(reach.held, reach.nodes);
  EXPECT_LE(holding_normal_length(patch, rim_node()), patch.normal_length);
  EXPECT_GT(holding_normal_length(patch, centre_node()), patch.normal_length);
  EXPECT_GE(reach.longest, holding_normal_length(patch, centre_node()));
  EXPECT_EQ(reach.longest, everywhere.longest);
  int independent = 0;  // counted again here
  for (int node = 0; node < patch.node_count(); ++node)
    independent += holding_normal_length(patch, node) <= patch.normal_length;
  EXPECT_EQ(reach.held, independent);
  const std::string warning = plateau_warning(reach, patch.normal_length);
  EXPECT_NE(warning.find(fmt::format("at {} of {} interface nodes", reach.held, reach.nodes)),
            std::string::npos)
      << warning;
  EXPECT_NE(warning.find(fmt::format("{:.2f} mm", 1e3 * reach.longest)), std::string::npos)
      << warning;
  std::printf("  %s\n", warning.c_str());
  // At the bound it holds everywhere.
  patch.normal_length = reach.longest;
  EXPECT_EQ(plateau_reach(patch).held, reach.nodes);
}

TEST(SeparationFracture, NormalPullShowsThePapersThreePhases) {
  const SeparationPatch& patch = default_two_layers().patch;
  const int node = rim_node();
  // The precondition for a flat BC: l_n is long enough for these fields at this node.
  ASSERT_LT(holding_normal_length(patch, node), patch.normal_length);
  PullLoopSettings settings;
  settings.node = node;
  const PullLoop loop = run_pull_loop(patch, make_separation_state(patch), settings);
  const Eigen::Vector3d n = patch.normals[patch.regions.of(node).front()];
  const double f_n = patch.toughness * patch.normal_length;
  ASSERT_DOUBLE_EQ(loop.threshold, f_n);

  int loading = 0, fracture = 0, unloading = 0;
  const PullLoopSample* b = nullptr;
  const PullLoopSample* c = nullptr;
  for (const PullLoopSample& s : loop.samples) {
    const Eigen::Vector3d delta = s.travel * n;
    switch (s.phase) {
      case PullPhase::loading:  // AB: the connected field F, nothing separated
        ++loading;
        EXPECT_NEAR(s.force, field_value(patch, node, 0, FieldState::connected, delta).force.dot(n),
                    1e-12 * f_n);
        EXPECT_EQ(s.separated_area, 0);
        b = &s;
        break;
      case PullPhase::fracture:  // BC: held at J_c l_n
        ++fracture;
        EXPECT_NEAR(s.force, f_n, 0.02 * f_n) << "at " << s.travel * 1e3 << " mm";
        c = &s;
        break;
      case PullPhase::unloading: {  // CA: D_n separated, F-bar (and the global share's F^e)
        ++unloading;
        EXPECT_EQ(s.local_separated, 1.0);
        const double f_bar =
            field_value(patch, node, 0, FieldState::locally_separated, delta).force.dot(n);
        const double f_e = field_value(patch, node, 0, FieldState::separated, delta).force.dot(n);
        const double global = s.separated_area / patch.interface_area;
        EXPECT_NEAR(s.force, (1 - global) * f_bar + global * f_e, 1e-12 * f_n);
        // F-bar, but for the global share's part of F^e and no more.
        EXPECT_LE(std::abs(s.force - f_bar), global * std::abs(f_bar - f_e) + 1e-12 * f_n)
            << "at " << s.travel * 1e3 << " mm";
        break;
      }
    }
  }
  EXPECT_GT(loading, 100);
  EXPECT_GT(fracture, 100);
  EXPECT_GT(unloading, 100);
  ASSERT_TRUE(b && c);
  EXPECT_NEAR(b->force, f_n, 1e-9 * f_n);  // B: where F reaches the threshold
  // BC: the separated area grew by l_n dz, and the hand's work paid for it at J_c.
  const double grown = c->separated_area - b->separated_area;
  EXPECT_NEAR(grown, patch.normal_length * (c->travel - b->travel), 1e-9 * grown);
  EXPECT_NEAR(loop.fracture_area, grown, 1e-15);
  EXPECT_NEAR(loop.fracture_work, patch.toughness * grown, 0.01 * patch.toughness * grown);
  // The loop: back to A with no force; the hand lost energy (passive), at most J_c dLambda.
  EXPECT_EQ(loop.samples.back().travel, 0);
  EXPECT_NEAR(loop.samples.back().force, 0, 1e-12);
  EXPECT_GT(loop.net_work, 0);
  EXPECT_LT(loop.net_work, patch.toughness * grown);
  // The figure: one line per phase, joined, and the threshold.
  const LinePlot figure = pull_loop_force_plot(loop);
  ASSERT_EQ(figure.series.size(), 4u);
  EXPECT_EQ(figure.series[0].x.size(), static_cast<std::size_t>(loading));
  EXPECT_EQ(figure.series[1].x.size(), static_cast<std::size_t>(fracture) + 1);
  EXPECT_EQ(figure.series[2].x.size(), static_cast<std::size_t>(unloading) + 1);
  EXPECT_EQ(figure.series[1].x.front(), figure.series[0].x.back());
  EXPECT_EQ(figure.series[3].y.front(), f_n);
  const std::string svg = render_svg(figure);
  std::size_t polylines = 0;
  for (std::size_t at = svg.find("<polyline"); at != std::string::npos;
       at = svg.find("<polyline", at + 1))
    ++polylines;
  EXPECT_EQ(polylines, 4u);
  const LinePlot shares = pull_loop_area_plot(loop, patch.interface_area);
  EXPECT_EQ(shares.series[0].y.back(), 1.0);
  RecordProperty("threshold_N", std::to_string(f_n));
  RecordProperty("fracture_work_J", std::to_string(loop.fracture_work));
  RecordProperty("Jc_dLambda_J", std::to_string(patch.toughness * grown));
}

// The energy balance holds whatever the speed (tick length) and the direction of the pull
// (Eq. 10, F . dx = J_c dLambda with dLambda = l_n dz + l_t dx_t): over BC the hand's work,
// integrated from the forces it feels, is J_c times the separated area, and the force
// along the pull stays at J_c l(direction). The loop is passive: the hand's work exceeds
// what the fields still store at the end.
TEST(SeparationFracture, EnergyBalanceAtOtherSpeedsAndAngles) {
  const SeparationPatch& patch = default_two_layers().patch;
  for (double speed : {0.002, 0.01, 0.05, 0.2})
    for (double tilt_deg : {0.0, 20.0, 40.0, 60.0})
      for (const Eigen::Vector3d& towards : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0)}) {
        if (tilt_deg == 0 && towards.y() == 1) continue;
        const double tilt = tilt_deg * std::numbers::pi / 180;
        PullLoopSettings settings;
        settings.node = rim_node();
        settings.speed = speed;
        settings.direction = std::cos(tilt) * Eigen::Vector3d::UnitZ() + std::sin(tilt) * towards;
        const PullLoop loop = run_pull_loop(patch, make_separation_state(patch), settings);
        const std::string where = "speed " + std::to_string(speed) + " m/s, tilt " +
                                  std::to_string(tilt_deg) + " deg towards " +
                                  (towards.x() == 1 ? "x" : "y");
        ASSERT_GT(loop.fracture_area, 0) << where;
        EXPECT_NEAR(loop.threshold,
                    patch.toughness * (patch.normal_length * std::cos(tilt) +
                                       patch.tangential_length * std::sin(tilt)),
                    1e-12)
            << where;
        EXPECT_NEAR(loop.fracture_work, patch.toughness * loop.fracture_area,
                    0.01 * patch.toughness * loop.fracture_area)
            << where;
        for (const PullLoopSample& s : loop.samples)
          if (s.phase == PullPhase::fracture) {
            EXPECT_NEAR(s.force, loop.threshold, 0.02 * loop.threshold)
                << where << " at " << s.travel * 1e3 << " mm";
          }
        EXPECT_GE(loop.net_work - loop.final_energy, 0) << where;
        EXPECT_GE(loop.final_energy, 0) << where;
      }
}

// A groove across the interface at x = 20.5 mm from y = 12 to 28 mm, cut at half v_s.
SeparationState grooved_across_the_middle(const SeparationPatch& patch) {
  SeparationState grooved = make_separation_state(patch);
  LaserFibre fibre;
  const double dt = 1e-3, speed = 0.5 * patch.vaporisation_speed;
  const Eigen::Vector3d from(0.0205, 0.012, 0), to(0.0205, 0.028, 0);
  const int ticks = static_cast<int>(std::ceil((to - from).norm() / (speed * dt)));
  for (int i = 0; i <= ticks; ++i)
    step_laser(patch, grooved, fibre, from + (to - from) * std::min(1.0, double(i) / ticks), true,
               dt);
  return grooved;
}

// The paper's scenario (Sec. VI.C): a laser groove, then a pull beside it. The crack grows
// from the groove's edge inside the interface, where the fields need a longer l_n than at
// the free rim; with the default l_n, which clears every node, BC holds at J_c l_n there
// too and the hand's work over it is J_c times the area. With an l_n below the node's
// holding length the plateau is lost as soon as the crack starts (the loop turns at once).
TEST(SeparationFracture, AGrooveThenAPullBesideItHoldsJcLnWhileTheCrackGrowsInside) {
  SeparationPatch patch = default_two_layers().patch;
  const SeparationState grooved = grooved_across_the_middle(patch);
  ASSERT_EQ(plateau_reach(patch).held, patch.node_count());
  for (double x : {0.020, 0.022})
    for (double y : {0.016, 0.020, 0.024}) {
      const int node = nearest_patch_node(patch, Eigen::Vector3d(x, y, 0));
      const std::string where = fmt::format("beside the groove at ({}, {}) mm", 1e3 * x, 1e3 * y);
      ASSERT_LT(holding_normal_length(patch, node), patch.normal_length) << where;
      PullLoopSettings settings;
      settings.node = node;
      const PullLoop loop = run_pull_loop(patch, grooved, settings);
      int fracture = 0;
      double lowest = loop.threshold, highest = loop.threshold;
      for (const PullLoopSample& s : loop.samples)
        if (s.phase == PullPhase::fracture) {
          ++fracture;
          lowest = std::min(lowest, s.force);
          highest = std::max(highest, s.force);
          EXPECT_NEAR(s.force, loop.threshold, 0.02 * loop.threshold)
              << where << " at " << s.travel * 1e3 << " mm";
        }
      EXPECT_GT(fracture, 100) << where;
      // The crack grew over the whole of the node's region (the loop's point C), at J_c.
      EXPECT_GE(loop.fracture_area, patch.region_areas[node]) << where;
      EXPECT_NEAR(loop.fracture_work, patch.toughness * loop.fracture_area,
                  0.01 * patch.toughness * loop.fracture_area)
          << where;
      EXPECT_GE(loop.net_work - loop.final_energy, 0) << where;

      SeparationPatch short_length = patch;
      short_length.normal_length = 0.5 * holding_normal_length(patch, node);
      short_length.normal_threshold = short_length.toughness * short_length.normal_length;
      const PullLoop lost = run_pull_loop(short_length, grooved, settings);
      EXPECT_LT(lost.fracture_area, 0.1 * patch.region_areas[node]) << where;
      std::printf(
          "  %s: BC %d samples, %.4f..%.4f N against J_c l_n = %.4f N, %.2f mm^2 separated, "
          "work %.4e J against J_c dLambda %.4e J; at l_n = %.2f mm, %.3f mm^2\n",
          where.c_str(), fracture, lowest, highest, loop.threshold, 1e6 * loop.fracture_area,
          loop.fracture_work, patch.toughness * loop.fracture_area,
          1e3 * short_length.normal_length, 1e6 * lost.fracture_area);
    }
}

// Drives a grasp at `node` along `direction` by `step` per tick until `stop` says so.
struct Push {
  SeparationState state;
  SeparationContact contact;
  std::vector<SeparationSample> samples;
  std::vector<double> travel;
};

template <typename Stop>
Push push(const SeparationPatch& patch, SeparationState state, int node,
          const Eigen::Vector3d& direction, double step, int max_ticks, const Stop& stop) {
  Push p{std::move(state), {}, {}, {}};
  const Eigen::Vector3d start = patch.positions.col(node);
  p.contact = begin_contact(patch, ContactMode::grasp, contact_at_node(patch, node), start);
  for (int i = 1; i <= max_ticks; ++i) {
    p.samples.push_back(step_contact(patch, p.state, p.contact, start + i * step * direction));
    p.travel.push_back(i * step);
    if (stop(p.samples.back())) break;
  }
  return p;
}

double tangential(const SeparationPatch& patch, const SeparationSample& s, int node) {
  const Eigen::Vector3d n = patch.normals[patch.regions.of(node).front()];
  return (s.body_force - s.body_force.dot(n) * n).norm();
}

// Pushed along the interface at a crack edge (the rim), the flap tears at F_t = J_c l_t:
// the force along the push holds there and l_t of area separates per metre the tool moves
// (Eqs. 4–11).
TEST(SeparationFracture, TangentialThresholdIsJcLt) {
  const SeparationPatch& patch = default_two_layers().patch;
  const int node = rim_node();
  const double f_t = patch.toughness * patch.tangential_length;
  const Push p = push(patch, make_separation_state(patch), node, Eigen::Vector3d::UnitX(), 1e-5,
                      800, [](const SeparationSample&) { return false; });
  std::size_t first = p.samples.size();
  for (std::size_t i = 0; i < p.samples.size(); ++i)
    if (p.samples[i].flags & kSeparationFracture) {
      first = i;
      break;
    }
  ASSERT_LT(first, p.samples.size() / 2) << "the push never tore the flap";
  for (std::size_t i = 0; i < first; ++i) {
    EXPECT_LT(p.samples[i].body_force.x(), f_t * (1 + 1e-9));
    EXPECT_EQ(p.samples[i].separated, 0);
  }
  double area = 0, work = 0;
  for (std::size_t i = first; i < p.samples.size(); ++i) {
    EXPECT_NEAR(p.samples[i].body_force.x(), f_t, 0.02 * f_t) << "tick " << i;
    area += p.samples[i].separated;
    if (i > first)
      work += 0.5 * (p.samples[i - 1].body_force + p.samples[i].body_force)
                        .dot(1e-5 * Eigen::Vector3d::UnitX());
  }
  const double travel = p.travel.back() - p.travel[first];
  EXPECT_NEAR(area - p.samples[first].separated, patch.tangential_length * travel,
              0.02 * patch.tangential_length * travel);
  EXPECT_NEAR(work, patch.toughness * (area - p.samples[first].separated), 0.01 * work);
  RecordProperty("tangential_plateau_N", std::to_string(p.samples.back().body_force.x()));
}

// "When there is no initial crack between bodies, the tool cannot cause fracture" (Sec.
// VI.C): away from the rim a push of ten times the thresholds separates nothing; after a
// laser groove through the contact's region the same push does.
TEST(SeparationFracture, NoCrackNoFractureUntilALaserGroove) {
  const SeparationPatch& patch = default_two_layers().patch;
  const int node = centre_node();
  const double f_t = patch.toughness * patch.tangential_length;
  const auto ten_times = [&](const SeparationSample& s) {
    return tangential(patch, s, node) >= 10 * f_t;
  };
  const Push intact = push(patch, make_separation_state(patch), node, Eigen::Vector3d::UnitX(),
                           2e-5, 5000, ten_times);
  ASSERT_TRUE(ten_times(intact.samples.back())) << "did not reach 10 F_t";
  EXPECT_EQ(intact.state.separated_area, 0);
  const Eigen::Vector3d n = patch.normals[patch.regions.of(node).front()];
  const Push pulled = push(patch, make_separation_state(patch), node, n, 2e-5, 5000,
                           [&](const SeparationSample& s) {
                             return s.body_force.dot(n) >= 10 * patch.normal_threshold;
                           });
  ASSERT_GE(pulled.samples.back().body_force.dot(n), 10 * patch.normal_threshold);
  EXPECT_EQ(pulled.state.separated_area, 0);

  const SeparationState grooved = grooved_across_the_middle(patch);
  const double groove = grooved.separated_area;
  ASSERT_GT(groove, 0);
  // The same push, 6 mm on from the node: it tears at F_t and goes on tearing, the
  // contact point carried along with the crack edge (Fig. 3).
  const Push opened = push(patch, grooved, node, Eigen::Vector3d::UnitX(), 2e-5, 300, ten_times);
  EXPECT_GT(opened.state.separated_area, groove + 1e-6) << "the push did not open the groove";
  double largest = 0;
  for (const SeparationSample& s : opened.samples) largest = std::max(largest, s.body_force.x());
  EXPECT_LT(largest, 1.02 * f_t);
  EXPECT_NEAR(opened.samples.back().body_force.x(), f_t, 0.02 * f_t);
  EXPECT_GT(opened.contact.position.x(), patch.positions(0, node) + 0.002)
      << "the contact point did not move on";
}

}  // namespace
}  // namespace cohaptic
