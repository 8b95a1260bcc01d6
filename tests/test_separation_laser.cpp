// Laser vaporisation at the separating interface: the steady
// speed from the energy balance (Eqs. 18–20, water's properties), the groove's area l_f L
// below that speed and nothing above it, and the strip geometry against exact areas.
#include <gtest/gtest.h>

#include <cmath>

#include "common/separation/laser_groove.h"
#include "common/separation/two_layer_setup.h"
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
  // A second pass over the groove adds nothing new where the first took everything.
  SeparationState twice = make_separation_state(patch);
  sweep(patch, twice, from, to, 0.5 * v_s);
  const double first = twice.separated_area;
  sweep(patch, twice, from, to, 0.5 * v_s);
  EXPECT_LE(twice.separated_area, 2 * first + 1e-18);
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
