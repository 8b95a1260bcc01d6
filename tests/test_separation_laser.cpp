// Laser vaporisation at the separating interface: the steady
// speed from the energy balance (Eqs. 18–20, water's properties), the groove's area l_f L
// below that speed and nothing above it, and the strip geometry against exact areas.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/separation/laser_groove.h"
#include "common/separation/separation_setup.h"
#include "common/util/error.h"
#include "support/default_two_layers.h"

namespace cohaptic {
namespace {

using testing::default_two_layers;

// Sweeps the fibre from `from` towards `to` at `speed` with 1 ms ticks, for as many whole
// ticks as fit; returns the area vaporised and sets `length` to the distance swept.
double sweep(const SeparationPatch& patch, SeparationState& state, const Eigen::Vector3d& from,
             const Eigen::Vector3d& to, double speed, bool on = true, double* length = nullptr) {
  LaserFibre fibre;
  const double dt = 1e-3;
  const Eigen::Vector3d step = (to - from).normalized() * speed * dt;
  const int ticks = static_cast<int>((to - from).norm() / (speed * dt));
  double area = 0;
  for (int i = 0; i <= ticks; ++i)
    area += step_laser(patch, state, fibre, from + i * step, on, dt).vaporised;
  if (length) *length = ticks * step.norm();
  return area;
}

TEST(SeparationLaser, VaporisationSpeedFromTheEnergyBalance) {
  // q = rho (c_p dT + H) for water from 37 degC: 1000 (4180 * 63 + 2.26e6) J/m^3.
  const double q = 1000.0 * (4180.0 * 63.0 + 2.26e6);
  EXPECT_DOUBLE_EQ(vaporisation_energy_density(TissueThermal{}), q);
  // v_s = alpha P / (q l_f^2) = 0.5 * 80 W / (q (0.55 mm)^2), about 52 mm/s.
  const double v_s = 0.5 * 80.0 / (q * 0.55e-3 * 0.55e-3);
  EXPECT_NEAR(vaporisation_speed(LaserSettings{}, TissueThermal{}), v_s, 1e-12 * v_s);
  EXPECT_NEAR(v_s, 0.0524, 0.0001);
  EXPECT_DOUBLE_EQ(default_two_layers().patch.vaporisation_speed, v_s);
  // Twice the power, twice the speed; twice the spot, a quarter.
  LaserSettings laser;
  laser.power *= 2;
  EXPECT_NEAR(vaporisation_speed(laser, TissueThermal{}), 2 * v_s, 1e-12 * v_s);
  laser.spot_diameter *= 2;
  EXPECT_NEAR(vaporisation_speed(laser, TissueThermal{}), 0.5 * v_s, 1e-12 * v_s);
  SeparationSettings bad;
  bad.laser.absorbed_fraction = 1.5;
  EXPECT_THROW(validate(bad), Error);
}

// Below v_s the groove follows the fibre: the area is l_f L, across every triangle it
// passes; above v_s nothing is removed; a held, switched-off or distant fibre removes nothing.
TEST(SeparationLaser, HalfSpeedVaporisesTheStripOneAndAHalfNothing) {
  const SeparationPatch& patch = default_two_layers().patch;
  const double v_s = patch.vaporisation_speed, l_f = patch.spot_diameter;
  // A slanted 17 mm path well inside the interface, crossing edges at all angles.
  const Eigen::Vector3d from(0.0113, 0.0087, 0), to(0.0261, 0.0171, 0);
  double length = 0;
  SeparationState slow = make_separation_state(patch);
  const double area = sweep(patch, slow, from, to, 0.5 * v_s, true, &length);
  EXPECT_GT(length, 0.016);
  EXPECT_NEAR(area, l_f * length, 1e-9 * l_f * length);
  EXPECT_NEAR(slow.separated_area, area, 1e-18);
  int open = 0;
  for (int t = 0; t < patch.triangle_count(); ++t) open += is_open(slow, t);
  EXPECT_GE(open, 10);  // a groove across many triangles, each now a crack edge

  SeparationState fast = make_separation_state(patch);
  EXPECT_EQ(sweep(patch, fast, from, to, 1.5 * v_s), 0);
  EXPECT_EQ(fast.separated_area, 0);
  SeparationState off = make_separation_state(patch);
  EXPECT_EQ(sweep(patch, off, from, to, 0.5 * v_s, false), 0);
  SeparationState above = make_separation_state(patch);
  const Eigen::Vector3d lift(0, 0, 2 * patch.laser_reach);
  EXPECT_EQ(sweep(patch, above, from + lift, to + lift, 0.5 * v_s), 0);
  SeparationState held = make_separation_state(patch);
  LaserFibre fibre;
  for (int i = 0; i < 100; ++i) step_laser(patch, held, fibre, from, true, 1e-3);
  EXPECT_EQ(held.separated_area, 0);
}

// Tissue is vaporised once: three passes over one line separate what the first did (l_f L),
// and two crossing grooves l_f (L1 + L2) less the square where they cross.
TEST(SeparationLaser, RepeatedAndCrossingPassesSeparateTheGrooveOnce) {
  const SeparationPatch& patch = default_two_layers().patch;
  const double v_s = patch.vaporisation_speed, l_f = patch.spot_diameter;
  const Eigen::Vector3d from(0.0113, 0.0087, 0), to(0.0261, 0.0171, 0);
  SeparationState thrice = make_separation_state(patch);
  double length = 0;
  const double first = sweep(patch, thrice, from, to, 0.5 * v_s, true, &length);
  EXPECT_NEAR(first, l_f * length, 1e-9 * l_f * length);
  EXPECT_EQ(sweep(patch, thrice, from, to, 0.5 * v_s), 0);
  // Back from where the first pass ended (short of `to`), at another speed.
  const Eigen::Vector3d end = from + length * (to - from).normalized();
  EXPECT_EQ(sweep(patch, thrice, end, from, 0.3 * v_s), 0);
  EXPECT_NEAR(thrice.separated_area, l_f * length, 1e-9 * l_f * length);
  EXPECT_EQ(thrice.groove.count, 1u) << "a straight stroke is one segment, and passes that "
                                        "vaporise nothing are not remembered";

  SeparationState crossed = make_separation_state(patch);
  double along_x = 0, along_y = 0;
  sweep(patch, crossed, Eigen::Vector3d(0.012, 0.013, 0), Eigen::Vector3d(0.026, 0.013, 0),
        0.5 * v_s, true, &along_x);
  sweep(patch, crossed, Eigen::Vector3d(0.019, 0.008, 0), Eigen::Vector3d(0.019, 0.018, 0),
        0.5 * v_s, true, &along_y);
  EXPECT_NEAR(crossed.separated_area, l_f * (along_x + along_y) - l_f * l_f, 0.03 * l_f * l_f);
}

// The record merges a stroke's ticks while they stay on one line, within 2 % of the width
// for every tick merged, starts a segment where the stroke turns, and says when it is full.
TEST(SeparationLaser, TheGrooveRecordMergesAStrokesTicksAndSaysWhenItIsFull) {
  const double width = 5e-4;
  GrooveRecord record;
  record.segments.resize(64);
  // An arc of radius 10 mm, 1 ms ticks at 26 mm/s: every tick end stays within the
  // tolerance of its segment's line.
  const double radius = 0.01, step = 2.6e-5;
  std::vector<Eigen::Vector3d> ticks;
  for (int i = 0; i <= 400; ++i)
    ticks.emplace_back(radius * std::cos(i * step / radius), radius * std::sin(i * step / radius),
                       0);
  for (std::size_t i = 1; i < ticks.size(); ++i)
    remember_groove(record, ticks[i - 1], ticks[i], width);
  EXPECT_GT(record.count, 3u) << "a 10 mm arc is not one straight segment";
  EXPECT_LT(record.count, 40u) << "ticks on a gentle arc merge";
  EXPECT_FALSE(record.full);
  for (const Eigen::Vector3d& p : ticks) {
    double nearest = 1;
    for (std::size_t k = 0; k < record.count; ++k) {
      const GrooveSegment& s = record.segments[k];
      const Eigen::Vector3d d = (s.b - s.a).normalized();
      const double along = (p - s.a).dot(d);
      if (along < -1e-12 || along > (s.b - s.a).norm() + 1e-12) continue;
      nearest = std::min(nearest, (p - s.a - along * d).norm());
    }
    EXPECT_LE(nearest, 0.02 * width + 1e-15);
  }
  // A right-angle turn starts a segment; a record with no room left says so.
  GrooveRecord small;
  small.segments.resize(2);
  const Eigen::Vector3d o(0, 0, 0), x(0.001, 0, 0), xy(0.001, 0.001, 0), y(0, 0.001, 0);
  remember_groove(small, o, x, width);
  remember_groove(small, x, xy, width);
  EXPECT_EQ(small.count, 2u);
  EXPECT_FALSE(small.full);
  remember_groove(small, xy, y, width);
  EXPECT_EQ(small.count, 2u);
  EXPECT_TRUE(small.full);
  // A state read from the wire has no buffer: it remembers nothing and vaporises as before.
  GrooveRecord none;
  remember_groove(none, o, x, width);
  EXPECT_EQ(none.count, 0u);
  EXPECT_EQ(uncovered_share(none, o, x, width, Eigen::Vector3d::UnitZ()), 1.0);
}

TEST(SeparationLaser, StripAreaIsTheExactIntersection) {
  const SeparationPatch& patch = default_two_layers().patch;
  const int t = 0;
  const Triangle& tri = patch.triangles[t];
  const Eigen::Vector3d a = patch.positions.col(tri[0]), b = patch.positions.col(tri[1]),
                        c = patch.positions.col(tri[2]);
  const Eigen::Vector3d centroid = (a + b + c) / 3;
  // A wide strip right over the triangle covers all of it.
  EXPECT_NEAR(strip_area_in_triangle(patch, t, centroid - Eigen::Vector3d(0.01, 0, 0),
                                     centroid + Eigen::Vector3d(0.01, 0, 0), 0.05),
              patch.areas[t], 1e-15);
  // A strip far away covers none of it.
  EXPECT_EQ(strip_area_in_triangle(patch, t, a + Eigen::Vector3d(0.01, 0.01, 0),
                                   a + Eigen::Vector3d(0.02, 0.01, 0), 1e-3),
            0);
  // A narrow strip along a line through a vertex and the opposite edge's midpoint, ending
  // inside: the intersection is that of the two half-strips with the triangle, here a
  // width w by the segment's length inside, to first order in w.
  const Eigen::Vector3d m = 0.5 * (b + c);
  const double w = 1e-6;
  const double expected = w * (m - a).norm();
  EXPECT_NEAR(strip_area_in_triangle(patch, t, a - (m - a), m + (m - a), w), expected,
              1e-3 * expected);
  // Strips from two halves of a segment add up to the strip of the whole segment.
  const Eigen::Vector3d p = a + 0.2 * (b - a) + 0.1 * (c - a),
                        q = a + 0.3 * (b - a) + 0.6 * (c - a);
  const Eigen::Vector3d half = 0.5 * (p + q);
  EXPECT_NEAR(strip_area_in_triangle(patch, t, p, half, 4e-4) +
                  strip_area_in_triangle(patch, t, half, q, 4e-4),
              strip_area_in_triangle(patch, t, p, q, 4e-4), 1e-15);
}

}  // namespace
}  // namespace cohaptic
