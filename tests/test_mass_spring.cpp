// The mass–spring model of the thin-objects paper against closed forms: the topology of
// Fig. 7, Eq. (1) and (2) by hand and the paper's Table 1, the integrator on a harmonic
// oscillator (its exact invariant, energy drift, critical step), a hanging chain's static
// sag and heating's inverse scaling of it, Coulomb friction on a plane (stick/slip
// threshold, acceleration, stopping distance), Eq. (5), the collision search of Sec. 4.2
// against a second closest-point method and the false collision of Fig. 8, and the tube's
// volume when bent.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <set>

#include "common/contact/closest_point_on_triangle.h"
#include "common/mass_spring/haptic_node_force.h"
#include "common/mass_spring/integrate_network.h"
#include "common/mass_spring/internal_forces.h"
#include "common/mass_spring/plane_friction.h"
#include "common/mass_spring/stable_time_step.h"
#include "common/mass_spring/surface_collision.h"
#include "common/mass_spring/thermal_stiffness.h"
#include "common/mass_spring/tool_coupling.h"
#include "common/mass_spring/tube_network.h"

namespace cohaptic {
namespace {

// Eq. 1 fixes only E r: with the paper's E, this radius gives its Table 1's springs.
constexpr double kRadius = 0.005;
constexpr double kSpacing = 0.0022245;
constexpr double kYoungsModulus = 737.4;  // [Pa]
constexpr double kG = 9.81;

TubeGeometry straight_tube(int sections, double radius = kRadius, double spacing = kSpacing) {
  TubeGeometry tube;
  const double lift =
      radius * std::cos(std::numbers::pi / kRingNodes);  // resting on its flat bottom face
  tube.centre_line = {Eigen::Vector3d(0, 0, lift),
                      Eigen::Vector3d(spacing * (sections - 1), 0, lift)};
  tube.radius = radius;
  tube.sections = sections;
  return tube;
}

TubeMaterial paper_material(double density = 9049) { return {kYoungsModulus, density, 1e-6}; }

const Spring& spring_between(const MassSpringNetwork& network, int a, int b) {
  for (const Spring& s : network.springs)
    if ((s.a == a && s.b == b) || (s.a == b && s.b == a)) return s;
  throw std::runtime_error("no such spring");
}

int centre(int section) { return kSectionNodes * section; }
int ring(int section, int k) { return kSectionNodes * section + 1 + (k + kRingNodes) % kRingNodes; }

TEST(MassSpringTube, NodeDegreesAreThoseOfFig7) {
  const MassSpringNetwork network = tube_network(straight_tube(6), paper_material());
  std::vector<std::set<int>> neighbours(static_cast<std::size_t>(network.node_count()));
  for (const Spring& s : network.springs) {
    neighbours[static_cast<std::size_t>(s.a)].insert(s.b);
    neighbours[static_cast<std::size_t>(s.b)].insert(s.a);
  }
  auto count = [&](int node, bool centres) {
    int n = 0;
    for (int other : neighbours[static_cast<std::size_t>(node)])
      n += (other % kSectionNodes == 0) == centres;
    return n;
  };
  for (int section = 1; section < 5; ++section) {
    EXPECT_EQ(count(centre(section), false), 24);
    EXPECT_EQ(count(centre(section), true), 2);
    for (int k = 0; k < kRingNodes; ++k) {
      EXPECT_EQ(count(ring(section, k), false), 8);
      EXPECT_EQ(count(ring(section, k), true), 3);
    }
  }
  // End sections miss the neighbours beyond the end.
  EXPECT_EQ(count(centre(0), false), 16);
  EXPECT_EQ(count(centre(0), true), 1);
  EXPECT_EQ(count(ring(0, 0), false), 5);
  EXPECT_EQ(count(ring(0, 0), true), 2);
}

TEST(MassSpringTube, StiffnessIsGeldersFormulaByHand) {
  // One wedge prism between two sections of a straight tube: (1/2) r^2 sin(45 deg) h.
  const double r = kRadius, h = kSpacing, E = kYoungsModulus;
  const double prism = 0.5 * r * r * std::sin(std::numbers::pi / 4) * h;
  const double chord = 2 * r * std::sin(std::numbers::pi / kRingNodes);
  const MassSpringNetwork network = tube_network(straight_tube(5), paper_material());
  struct Case {
    int a, b;
    int prisms;
    double length;
  };
  const Case cases[] = {
      {ring(2, 0), ring(2, 1), 2, chord},                 // ring edge: one prism each side
      {ring(2, 0), ring(3, 0), 2, h},                     // longitudinal
      {ring(2, 0), ring(3, 1), 1, std::hypot(chord, h)},  // diagonal
      {centre(2), ring(2, 0), 4, r},                      // spoke
      {centre(2), ring(3, 0), 2, std::hypot(r, h)},       // centre to the next ring
      {centre(2), centre(3), 8, h},                       // centre to centre
      {ring(0, 0), ring(0, 1), 1, chord},                 // ring edge at the end
  };
  for (const Case& c : cases) {
    const Spring& s = spring_between(network, c.a, c.b);
    EXPECT_NEAR(s.rest_length, c.length, 1e-12);
    EXPECT_NEAR(s.stiffness, E * c.prisms * prism / (c.length * c.length), 1e-9 * s.stiffness)
        << c.a << "-" << c.b;
    EXPECT_NEAR(s.damping, 1e-6 * s.stiffness, 1e-18);  // Eq. (2)
  }
  // Eq. (1) scales with E and, at a fixed shape, with size (volume / length^2).
  TubeMaterial stiffer = paper_material();
  stiffer.youngs_modulus *= 3;
  const MassSpringNetwork scaled_e = tube_network(straight_tube(5), stiffer);
  const MassSpringNetwork doubled =
      tube_network(straight_tube(5, 2 * kRadius, 2 * kSpacing), paper_material());
  for (std::size_t i = 0; i < network.springs.size(); ++i) {
    EXPECT_NEAR(scaled_e.springs[i].stiffness, 3 * network.springs[i].stiffness,
                1e-9 * network.springs[i].stiffness);
    EXPECT_NEAR(doubled.springs[i].stiffness, 2 * network.springs[i].stiffness,
                1e-9 * network.springs[i].stiffness);
  }
}

TEST(MassSpringTube, ReproducesTable1AtThePapersGeometry) {
  // Table 1 (Fig. 12's numbering: 1-4 surface, 5 and 6 centres), in N/m.
  const MassSpringNetwork network = tube_network(straight_tube(5), paper_material());
  const std::pair<double, double> table[] = {
      {spring_between(network, ring(2, 0), ring(2, 1)).stiffness, 1.98},
      {spring_between(network, ring(2, 0), ring(3, 0)).stiffness, 5.86},
      {spring_between(network, ring(2, 0), ring(3, 1)).stiffness, 0.74},
      {spring_between(network, ring(2, 0), centre(2)).stiffness, 2.32},
      {spring_between(network, ring(2, 0), centre(3)).stiffness, 0.96},
      {spring_between(network, centre(2), centre(3)).stiffness, 23.24},
  };
  for (const auto& [ours, paper] : table) EXPECT_NEAR(ours, paper, 0.015 * paper);
}

TEST(MassSpringTube, MassIsDensityTimesVolumeAndTheSurfaceIsClosed) {
  const MassSpringNetwork network = tube_network(straight_tube(10), paper_material());
  const double area = 0.5 * kRingNodes * kRadius * kRadius *
                      std::sin(2 * std::numbers::pi / kRingNodes);  // octagon
  const double volume = area * 9 * kSpacing;
  EXPECT_NEAR(network.mass.sum(), 9049 * volume, 1e-12);
  EXPECT_NEAR(enclosed_volume(network, network.rest_positions), volume, 1e-12 * volume);
}

// A free node on a spring to a held node.
MassSpringNetwork oscillator(double mass, double stiffness) {
  MassSpringNetwork network;
  network.rest_positions = Eigen::Matrix3Xd::Zero(3, 2);
  network.rest_positions(0, 1) = 1;
  network.mass = Eigen::Vector2d(1, mass);
  network.held = {1, 0};
  network.springs.push_back({0, 1, 1.0, stiffness, 0});
  network.parameters.gravity.setZero();
  network.parameters.time_step = 1;
  index_surface(network);
  return network;
}

TEST(MassSpringIntegrator, ConservesItsInvariantAndDoesNotDriftOnAHarmonicOscillator) {
  const double m = 0.002, k = 8, omega = std::sqrt(k / m), h = 0.5 / omega;
  const MassSpringNetwork network = oscillator(m, k);
  MassSpringState state = make_state(network);
  state.positions(0, 1) = 1.01;
  // Semi-implicit Euler conserves Q = v^2 + w^2 x^2 - h w^2 x v exactly (x the stretch);
  // the energy itself oscillates by O(w h) within a period but must not drift.
  auto invariant = [&] {
    const double x = state.positions(0, 1) - 1, v = state.velocities(0, 1);
    return v * v + omega * omega * x * x - h * omega * omega * x * v;
  };
  auto energy = [&] {
    return kinetic_energy(network, state.velocities) + potential_energy(network, state.positions);
  };
  const double q0 = invariant();
  const int period_steps = static_cast<int>(std::round(2 * std::numbers::pi / (omega * h)));
  double first_period = 0, last_period = 0;
  const int steps = 100000;
  for (int i = 0; i < steps; ++i) {
    step_network(network, state, {}, {}, h);
    if (i < period_steps) first_period += energy();
    if (i >= steps - period_steps) last_period += energy();
  }
  EXPECT_NEAR(invariant() / q0, 1, 1e-9);
  EXPECT_NEAR(last_period / first_period, 1, 0.01);
}

bool stays_bounded(const MassSpringNetwork& network, double h) {
  MassSpringState state = make_state(network);
  state.positions(0, 1) = 1.001;
  for (int i = 0; i < 4000; ++i) step_network(network, state, {}, {}, h);
  return std::abs(state.positions(0, 1) - 1) < 0.01;
}

TEST(MassSpringIntegrator, CriticalStepIsTwoRootMOverK) {
  const double m = 0.003, k = 12, expected = 2 * std::sqrt(m / k);
  const MassSpringNetwork network = oscillator(m, k);
  double stable = 0.1 * expected, unstable = 10 * expected;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (stable + unstable);
    (stays_bounded(network, mid) ? stable : unstable) = mid;
  }
  EXPECT_NEAR(stable, expected, 0.02 * expected);
  EXPECT_NEAR(critical_time_step(network), expected, 1e-6 * expected);

  // Damped (c = d/m): stable while h^2 k/m + 2 h c < 4, bisected as above.
  MassSpringNetwork damped = network;
  damped.springs[0].damping = 0.5 * std::sqrt(k * m);
  const double omega = std::sqrt(k / m), xi = damped.springs[0].damping / m / (2 * omega);
  const double damped_expected = 2 / omega * (std::sqrt(1 + xi * xi) - xi);
  stable = 0.1 * damped_expected;
  unstable = 10 * damped_expected;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (stable + unstable);
    (stays_bounded(damped, mid) ? stable : unstable) = mid;
  }
  EXPECT_NEAR(stable, damped_expected, 0.02 * damped_expected);
  EXPECT_NEAR(critical_time_step(damped), damped_expected, 1e-6 * damped_expected);
}

// A vertical chain of `count` masses m hanging from a held node by springs k.
MassSpringNetwork hanging_chain(int count, double m, double k, double length) {
  MassSpringNetwork network;
  network.rest_positions = Eigen::Matrix3Xd::Zero(3, count + 1);
  network.mass = Eigen::VectorXd::Constant(count + 1, m);
  network.held.assign(static_cast<std::size_t>(count) + 1, 0);
  network.held[0] = 1;
  for (int i = 1; i <= count; ++i) {
    network.rest_positions(2, i) = -length * i;
    network.springs.push_back({i - 1, i, length, k, 0.05 * k});
  }
  network.parameters.node_damping = 0.002;
  network.parameters.time_step = 0.2 * critical_time_step(network);
  index_surface(network);
  return network;
}

double settle_and_sag(const MassSpringNetwork& network) {
  MassSpringState state = make_state(network);
  for (int i = 0; i < 200000; ++i)
    step_network(network, state, {}, {}, network.parameters.time_step);
  return network.rest_positions(2, network.node_count() - 1) -
         state.positions(2, network.node_count() - 1);
}

TEST(MassSpringStatics, ChainSagsByTheClosedFormAndHeatingScalesItByTheInverseFactor) {
  const int count = 6;
  const double m = 0.001, k = 4;
  MassSpringNetwork chain = hanging_chain(count, m, k, 0.01);
  const double expected =
      m * kG / k * count * (count + 1) / 2;  // spring i carries the weight below it
  EXPECT_NEAR(settle_and_sag(chain), expected, 1e-6 * expected);

  HeatedRegion everywhere{Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1), 40, 1.2e-4,
                          100};
  const double factor = thermal_stiffness_factor(everywhere);
  ASSERT_NEAR(factor, 1 - 100 * 1.2e-4 * 40, 1e-15);
  MassSpringNetwork heated = chain;
  EXPECT_EQ(heat_springs(heated, everywhere), count);
  for (std::size_t s = 0; s < chain.springs.size(); ++s) {
    EXPECT_DOUBLE_EQ(heated.springs[s].stiffness, factor * chain.springs[s].stiffness);
    EXPECT_DOUBLE_EQ(heated.springs[s].damping, factor * chain.springs[s].damping);
  }
  EXPECT_NEAR(settle_and_sag(heated), expected / factor, 1e-6 * expected / factor);
}

TEST(MassSpringStatics, HeatingHalfATubeScalesExactlyTheSpringsInside) {
  const MassSpringNetwork cold = tube_network(straight_tube(10), paper_material());
  MassSpringNetwork warm = cold;
  const double middle = 4.5 * kSpacing;
  HeatedRegion half{Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(middle, 1, 1), 30, 1e-4, 100};
  const int heated = heat_springs(warm, half);
  int inside = 0;
  for (std::size_t s = 0; s < cold.springs.size(); ++s) {
    const bool hot = cold.rest_positions(0, cold.springs[s].a) <= middle &&
                     cold.rest_positions(0, cold.springs[s].b) <= middle;
    inside += hot;
    EXPECT_DOUBLE_EQ(warm.springs[s].stiffness, (hot ? 0.7 : 1.0) * cold.springs[s].stiffness);
  }
  EXPECT_EQ(heated, inside);
  EXPECT_GT(inside, 100);
}

MassSpringNetwork tube_on_plane(int sections, double density, const Eigen::Vector3d& gravity) {
  MassSpringNetwork network = tube_network(straight_tube(sections), paper_material(density));
  network.parameters.gravity = gravity;
  network.parameters.node_damping = 0.007;
  network.parameters.plane =
      SupportPlane{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.5, 0.2};
  network.parameters.time_step = 0.5 * critical_time_step(network);
  return network;
}

// The friction closed forms are a rigid block's without air drag: the tube 100 times stiffer
// (its own wobble then negligible) and no nodal damping (-beta v acts like air drag).
MassSpringNetwork rigid_tube_on_plane(int sections, const Eigen::Vector3d& gravity) {
  MassSpringNetwork network =
      tube_network(straight_tube(sections), {100 * kYoungsModulus, 9049, 1e-3});
  network.parameters.gravity = gravity;
  network.parameters.plane =
      SupportPlane{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.5, 0.2};
  network.parameters.time_step = 0.5 * critical_time_step(network);
  return network;
}

void run(const MassSpringNetwork& network, MassSpringState& state, double seconds) {
  const int steps = static_cast<int>(std::round(seconds / network.parameters.time_step));
  for (int i = 0; i < steps; ++i)
    step_network(network, state, {}, {}, network.parameters.time_step);
}

Eigen::Vector3d centre_of_mass(const MassSpringNetwork& network, const MassSpringState& state) {
  return state.positions * network.mass / network.mass.sum();
}

// Gravity tilted by angle a from the plane's normal: tan a below mu_s holds, above slides
// at g (sin a - mu_d cos a). The tilt grows over 0.3 s (quasi-statically: a sudden tilt
// would load the elastic tube's contacts up to twice the static pull for a moment), then
// the nodes on the plane must not move, or the centre of mass must move by v0 t + a t^2 / 2 over
// the next 0.2 s. (Close below mu_s, at tan a = 0.45, the elastic tube creeps: its contact nodes do
// not share the pull evenly, the most loaded slip and hand their load on.)
TEST(MassSpringFriction, StaysBelowTheStaticThresholdAndAcceleratesByTheDynamicLawAbove) {
  for (const double tilt : {0.3, 0.55, 0.8}) {  // tan of the tilt; mu_s = 0.5, mu_d = 0.2
    const double angle = std::atan(tilt);
    MassSpringNetwork network = rigid_tube_on_plane(8, Eigen::Vector3d(0, 0, -kG));
    MassSpringState state = make_state(network);
    run(network, state, 0.5);
    state.velocities.setZero();
    const Eigen::Vector3d rest = centre_of_mass(network, state);
    const MassSpringState settled = state;
    const int ramp_steps = static_cast<int>(std::round(0.3 / network.parameters.time_step));
    for (int i = 1; i <= ramp_steps; ++i) {
      const double a = angle * i / ramp_steps;
      network.parameters.gravity = Eigen::Vector3d(kG * std::sin(a), 0, -kG * std::cos(a));
      step_network(network, state, {}, {}, network.parameters.time_step);
    }
    const Eigen::Vector3d start = centre_of_mass(network, state);
    const double v0 = (state.velocities * network.mass / network.mass.sum()).x();
    const double seconds = 0.2;
    run(network, state, seconds);
    const double moved = centre_of_mass(network, state).x() - start.x();
    if (tilt < 0.5) {
      // The tube leans elastically; the nodes on the plane stay where they were (within a
      // micrometre: a contact that lifts for a step and lands again), where sliding at the
      // dynamic law would have taken them centimetres.
      double slid = 0;
      for (int n = 0; n < network.node_count(); ++n)
        if (settled.positions(2, n) <= kPlaneTouchTolerance)
          slid =
              std::max(slid, (state.positions.col(n) - settled.positions.col(n)).head<2>().norm());
      EXPECT_LT(slid, 2e-6) << "tilt " << tilt;
      EXPECT_LT(std::abs(centre_of_mass(network, state).x() - rest.x()), 1e-4) << "tilt " << tilt;
    } else {
      const double acceleration = kG * (std::sin(angle) - 0.2 * std::cos(angle));
      const double expected = v0 * seconds + 0.5 * acceleration * seconds * seconds;
      EXPECT_NEAR(moved, expected, 0.05 * expected) << "tilt " << tilt;
    }
  }
}

// Coulomb's law on one node pressed onto the plane by F_n = m g: sliding, it feels mu_d F_n
// against its motion until mu_d F_n can stop it within the step; at rest, a pull below
// mu_s F_n is cancelled and one above it is met by mu_s F_n.
TEST(MassSpringFriction, ASlidingNodeFeelsTheDynamicLawUntilItCanStopAndANodeAtRestTheStaticOne) {
  const SupportPlane plane{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.5, 0.2};
  const double m = 2e-4, h = 1e-3, load = m * kG;
  const Eigen::Vector3d x = Eigen::Vector3d::Zero(), weight(0, 0, -load);
  bool sliding = false;
  // Sliding at a speed that mu_s F_n could stop within the step but mu_d F_n cannot.
  const double speed = 0.35 * load * h / m;
  const Eigen::Vector3d slow =
      plane_reaction(plane, x, Eigen::Vector3d(speed, 0, 0), weight, m, h, sliding);
  EXPECT_TRUE(sliding);
  EXPECT_NEAR(slow.x(), -0.2 * load, 1e-15);
  EXPECT_NEAR(slow.z(), load, 1e-15);
  // Slow enough for mu_d F_n to stop: stopped exactly.
  const Eigen::Vector3d stopped =
      plane_reaction(plane, x, Eigen::Vector3d(0.1 * load * h / m, 0, 0), weight, m, h, sliding);
  EXPECT_FALSE(sliding);
  EXPECT_NEAR(stopped.x(), -0.1 * load, 1e-15);
  // At rest, pulled by 0.35 F_n: held; by 0.6 F_n: mu_s F_n against the pull.
  const Eigen::Vector3d held =
      plane_reaction(plane, x, Eigen::Vector3d::Zero(), weight + Eigen::Vector3d(0.35 * load, 0, 0),
                     m, h, sliding);
  EXPECT_NEAR(held.x(), -0.35 * load, 1e-15);
  const Eigen::Vector3d broke = plane_reaction(
      plane, x, Eigen::Vector3d::Zero(), weight + Eigen::Vector3d(0.6 * load, 0, 0), m, h, sliding);
  EXPECT_NEAR(broke.x(), -0.5 * load, 1e-15);
}

TEST(MassSpringFriction, SlidingTubeStopsAfterVSquaredOverTwoMuG) {
  const MassSpringNetwork network = rigid_tube_on_plane(8, Eigen::Vector3d(0, 0, -kG));
  MassSpringState state = make_state(network);
  run(network, state, 0.5);
  const double v0 = 0.2;
  state.velocities.row(0).setConstant(v0);
  const Eigen::Vector3d start = centre_of_mass(network, state);
  run(network, state, 1.0);  // stops after v0 / (mu_d g) = 0.1 s
  const double expected = v0 * v0 / (2 * 0.2 * kG);
  EXPECT_NEAR(centre_of_mass(network, state).x() - start.x(), expected, 0.05 * expected);
  EXPECT_LT(state.velocities.norm(), 1e-6);
}

// Dropped from 20 mm, the rigid tube falls freely (semi-implicit Euler's fall after n steps
// of h is g h^2 n (n + 1) / 2, within 1 % of g t^2 / 2 here), lands without bouncing
// (Eq. 6: an inelastic contact) and rests with every node on or above the plane, at the
// height it had when it was set on the plane.
TEST(MassSpringFriction, DroppedTubeFallsByHalfGTSquaredAndRestsOnThePlane) {
  const MassSpringNetwork network = rigid_tube_on_plane(8, Eigen::Vector3d(0, 0, -kG));
  MassSpringState resting = make_state(network);
  run(network, resting, 0.3);
  MassSpringState state = make_state(network);
  state.positions.row(2).array() += 0.02;
  const double start = centre_of_mass(network, state).z();
  const int falling = static_cast<int>(std::round(0.05 / network.parameters.time_step));
  for (int i = 0; i < falling; ++i)
    step_network(network, state, {}, {}, network.parameters.time_step);
  const double t = falling * network.parameters.time_step;
  EXPECT_NEAR(start - centre_of_mass(network, state).z(), 0.5 * kG * t * t,
              0.01 * 0.5 * kG * t * t);
  double lowest = 1;
  for (int i = 0; i < static_cast<int>(0.5 / network.parameters.time_step); ++i) {
    step_network(network, state, {}, {}, network.parameters.time_step);
    lowest = std::min(lowest, state.positions.row(2).minCoeff());
  }
  EXPECT_GE(lowest, 0.0);
  EXPECT_NEAR(centre_of_mass(network, state).z(), centre_of_mass(network, resting).z(), 2e-5);
  EXPECT_LT(state.velocities.cwiseAbs().maxCoeff(), 1e-3);
}

TEST(MassSpringFriction, NoNodeGoesBelowThePlaneWhenDropped) {
  MassSpringNetwork network = tube_on_plane(12, 1508, Eigen::Vector3d(0, 0, -kG));
  MassSpringState state = make_state(network);
  state.positions.row(2).array() += 0.02;
  // Tumbling: a spin about the tube's axis and a tilt, so that it lands unevenly.
  for (int n = 0; n < network.node_count(); ++n)
    state.velocities.col(n) =
        Eigen::Vector3d(0, 0.3 * state.positions(2, n) / 0.02, -0.5 + 2 * state.positions(0, n));
  double lowest = 1;
  // Nodal damping -beta v holds this light tube's fall to about 4 cm/s: 1.5 s to land.
  const int steps = static_cast<int>(1.5 / network.parameters.time_step);
  for (int i = 0; i < steps; ++i) {
    step_network(network, state, {}, {}, network.parameters.time_step);
    lowest = std::min(lowest, state.positions.row(2).minCoeff());
  }
  EXPECT_GE(lowest, 0.0);
  EXPECT_LT(lowest, 1e-9);  // it did land
}

TEST(MassSpringHaptic, Eq5PutsTheContactNodeOnItsCommandedPosition) {
  MassSpringNetwork network = tube_on_plane(6, 9049, Eigen::Vector3d(0, 0, -kG));
  network.parameters.tool_friction =
      std::numeric_limits<double>::infinity();  // no slip: exactly on target
  MassSpringState state = make_state(network);
  state.velocities.setRandom();
  state.velocities *= 0.01;
  const int node = ring(3, 1);  // on the upper side
  NodeDrive drive{node,
                  Eigen::Vector3d(state.positions.col(node)) + Eigen::Vector3d(0.0002, 0, -0.001),
                  Eigen::Vector3d(0, 0, 1)};
  Eigen::Vector3d applied;
  step_network(network, state, std::span(&drive, 1), std::span(&applied, 1),
               network.parameters.time_step);
  EXPECT_LT((state.positions.col(node) - drive.target).norm(), 1e-15);
  EXPECT_LT(applied.z(), 0);  // pushed down

  // A mostly tangential command: the tangential force is capped at mu |normal force|.
  MassSpringState again = make_state(network);
  const HapticNodeForce capped = haptic_node_force(
      network.mass[node], again.positions.col(node), Eigen::Vector3d::Zero(),
      Eigen::Vector3d::Zero(),
      Eigen::Vector3d(again.positions.col(node)) + Eigen::Vector3d(0.001, 0, -0.0001),
      Eigen::Vector3d::UnitZ(), 0.3, 1e-3);
  EXPECT_TRUE(capped.slipped);
  EXPECT_NEAR(std::hypot(capped.force.x(), capped.force.y()), 0.3 * std::abs(capped.force.z()),
              1e-15);
}

TEST(MassSpringCollision, FaceSearchMatchesASecondClosestPointMethod) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-1, 1);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d a(uniform(random), uniform(random), uniform(random)),
        b(uniform(random), uniform(random), 0), c(uniform(random), 0, uniform(random)),
        p(2 * uniform(random), 2 * uniform(random), 2 * uniform(random));
    const Eigen::Vector3d ours = closest_point_on_face(p, a, b, c);
    const Eigen::Vector3d theirs = closest_point_on_triangle(p, a, b, c).point;
    EXPECT_NEAR((ours - p).norm(), (theirs - p).norm(), 1e-12);
  }
}

TEST(MassSpringCollision, ConvexCornerOfFig8IsNoCollisionForTheFaceTest) {
  const MassSpringNetwork network = tube_network(straight_tube(5), paper_material());
  // The flat top face of section 2's octagon: ring nodes 7 and 0, at -22.5 and 22.5 degrees
  // from the vertical.
  const int a = ring(2, 7), b = ring(2, 0);
  const Eigen::Vector3d midpoint =
      0.5 * (network.rest_positions.col(a) + network.rest_positions.col(b));
  const Eigen::Vector3d outward(0, 0, 1);
  ASSERT_NEAR((network.rest_positions.col(a) - midpoint).dot(outward), 0,
              1e-12);  // a flat top face
  // Just above the face, a little nearer node b than node a.
  const Eigen::Vector3d tool = midpoint + 0.0002 * outward +
                               0.0003 * (network.rest_positions.col(b) - midpoint).normalized();
  // The nearest-node test: (x_sn - x_h) . N_sn >= 0 with the node's radial normal.
  const Eigen::Vector3d node_normal =
      (network.rest_positions.col(b) - network.rest_positions.col(centre(2))).normalized();
  EXPECT_GE((network.rest_positions.col(b) - tool).dot(node_normal), 0)
      << "the nearest-node test collides";
  const SurfaceContact contact = find_surface_contact(network, network.rest_positions, tool, 0);
  EXPECT_EQ(contact.nearest_node, b);
  EXPECT_FALSE(contact.colliding);
  EXPECT_NEAR(contact.depth, -0.0002, 1e-12);
  // Pressed below the face, it collides.
  EXPECT_TRUE(
      find_surface_contact(network, network.rest_positions, tool - 0.0004 * outward, 0).colliding);
}

// The paper (Sec. 5) found the volume to change by at most 2 % without volume-conserving
// forces. The volume is the divergence theorem's sum over the closed surface's triangles,
// checked against the octagonal prism's formula above. The tube is bent on its plane by
// its end sections, held (they move at their own velocity): the left end stays, the right
// end is carried 12 mm sideways over 1.2 s, then both rest. (A tool pushing the tube's
// side bends it too: TubeBentByAToolKeepsItsVolumeWithinTwoPercent, below.)
TEST(MassSpringStatics, BentTubeKeepsItsVolumeWithinTwoPercent) {
  const int sections = 20;
  MassSpringNetwork network = tube_on_plane(sections, 9049, Eigen::Vector3d(0, 0, -kG));
  MassSpringState state = make_state(network);
  run(network, state, 0.3);
  const double rest_volume = enclosed_volume(network, state.positions);
  const auto end_nodes = [&](int section) {
    std::vector<int> nodes;
    for (int k = 0; k < kSectionNodes; ++k) nodes.push_back(kSectionNodes * section + k);
    return nodes;
  };
  for (const int section : {0, sections - 1})
    for (int n : end_nodes(section)) {
      network.held[static_cast<std::size_t>(n)] = 1;
      state.velocities.col(n).setZero();
    }
  for (int n : end_nodes(sections - 1)) state.velocities(1, n) = 0.01;
  run(network, state, 1.2);
  for (int n : end_nodes(sections - 1)) state.velocities.col(n).setZero();
  run(network, state, 0.5);
  const double middle = state.positions(1, centre(sections / 2)),
               left = state.positions(1, centre(0)),
               right = state.positions(1, centre(sections - 1));
  EXPECT_NEAR(right - left, 0.012, 1e-5);
  // Friction on the plane holds the middle back: far off the straight chord's 6 mm.
  EXPECT_GT(middle - left, 0.0002) << "the middle followed a little";
  EXPECT_LT(middle - left, 0.003) << "the tube bent";
  EXPECT_GE(state.positions.row(2).minCoeff(), 0.0);
  const double ratio = enclosed_volume(network, state.positions) / rest_volume;
  EXPECT_NEAR(ratio, 1, 0.02);
  std::printf("bent tube: middle %.2f mm off, volume ratio %.4f\n", 1000 * (middle - left), ratio);
}

// The volume of a tube bent by a tool. A 2 mm sphere pushes the middle of a resting tube
// (20 sections) sideways along the plane, 12 mm at 10 mm/s, and holds; the plane's friction
// holds the rest back, so the tube bends around the tool (the driven node follows the tool,
// tool_coupling.h). The tube is 10 times stiffer than the paper's and its springs damped at
// alpha = 1e-4 s: the paper's E = 737 Pa tube, flattened to half its height by its own
// weight, is crushed by the tool (its volume falls to about a quarter; docs/mass-spring.md,
// what to set for a drag by a tool). At the paper's alpha = 1e-6 s the stiffer tube bends alike
// (middle 10.15 mm, ends 5.95 mm, volume ratio 0.9961, measured once).
TEST(MassSpringStatics, TubeBentByAToolKeepsItsVolumeWithinTwoPercent) {
  const int sections = 20;
  MassSpringNetwork network =
      tube_network(straight_tube(sections), {10 * kYoungsModulus, 9049, 1e-4});
  network.parameters.gravity = Eigen::Vector3d(0, 0, -kG);
  network.parameters.node_damping = 0.007;
  network.parameters.plane =
      SupportPlane{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.5, 0.2};
  network.parameters.tool_friction = 0.3;
  network.parameters.time_step = 0.5 * critical_time_step(network);
  MassSpringState state = make_state(network);
  run(network, state, 0.3);
  const double rest_volume = enclosed_volume(network, state.positions);
  const int middle = centre(sections / 2);
  const double radius = 0.002, speed = 0.01, period = 1e-3;
  const double side = state.positions.row(1).minCoeff();
  const Eigen::Vector3d start(state.positions(0, middle), side - radius - 0.0005, 0.002);
  const Eigen::VectorXd start_y = state.positions.row(1).transpose();
  std::array<ToolPress, 1> press;
  std::array<NetworkToolReaction, 1> reaction;
  double largest = 0, lowest = 1;
  int in_contact = 0;
  for (int i = 1; i <= 1700; ++i) {
    const std::array<ToolOnNetwork, 1> tool{
        ToolOnNetwork{start + Eigen::Vector3d(0, speed * std::min(i, 1200) * period, 0), radius}};
    advance_with_tools(network, state, tool, press, reaction, period);
    ASSERT_TRUE(reaction[0].force.allFinite()) << "period " << i;
    largest = std::max(largest, reaction[0].force.norm());
    lowest = std::min(lowest, state.positions.row(2).minCoeff());
    in_contact += reaction[0].colliding;
  }
  const auto moved = [&](int node) { return state.positions(1, node) - start_y[node]; };
  const double middle_moved = moved(middle),
               ends_moved = 0.5 * (moved(centre(0)) + moved(centre(sections - 1)));
  const double ratio = enclosed_volume(network, state.positions) / rest_volume;
  std::printf(
      "bent by a tool: middle moved %.2f mm, ends %.2f mm, largest force %.3f N, volume ratio "
      "%.4f, "
      "%d periods in contact\n",
      1e3 * middle_moved, 1e3 * ends_moved, largest, ratio, in_contact);
  EXPECT_GT(middle_moved, 0.009) << "the tool pushed the tube, it did not sink through it";
  EXPECT_LT(ends_moved, middle_moved - 0.001) << "the tube bent";
  EXPECT_GE(lowest, 0.0);
  EXPECT_LT(largest, 1.0);
  EXPECT_NEAR(ratio, 1, 0.02);
}

}  // namespace
}  // namespace cohaptic
