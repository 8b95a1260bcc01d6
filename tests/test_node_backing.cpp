// The backing a body behind a mass-spring network gives its nodes (node_backing.h): a
// unilateral contact per node through the behind body's dense normal compliance, solved at
// every evaluation. Checked against independent answers: a dropped node comes to rest at
// its weight times its compliance (statics) without ever gaining energy; a contact never
// pulls; two coupled nodes get the closed-form pushes of the 2x2 complementarity problem,
// and a shallow node beside a deep one is released (which one spring per node, the
// lumped form, cannot do); a network of coupled nodes dropped on an undamped backing
// never gains energy; a sub-network's backing with the other nodes' pushes held gives the
// whole backing's pushes.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>
#include <random>

#include "common/mass_spring/integrate_network.h"
#include "common/mass_spring/internal_forces.h"
#include "common/mass_spring/node_backing.h"

namespace cohaptic {
namespace {

// Backed nodes 0..count-1 with targets on the plane z = 0 (normal +z), x apart by 10 mm.
NodeBacking plane_backing(const Eigen::MatrixXd& compliance, double damping) {
  const auto count = compliance.rows();
  NodeBacking backing;
  backing.compliance = compliance;
  backing.offsets = Eigen::VectorXd::Zero(count);
  backing.damping = Eigen::VectorXd::Constant(count, damping);
  backing.targets = Eigen::VectorXd::Zero(3 * count);
  backing.normals = Eigen::VectorXd::Zero(3 * count);
  for (Eigen::Index i = 0; i < count; ++i) {
    backing.nodes.push_back(static_cast<int>(i));
    backing.targets[3 * i] = 0.01 * static_cast<double>(i);
    backing.normals[3 * i + 2] = 1;
  }
  return backing;
}

NodeBacking one_node_backing(double stiffness, double damping) {
  return plane_backing(Eigen::MatrixXd::Constant(1, 1, 1 / stiffness), damping);
}

// The pushes at node heights `z` (over the targets), at rest.
Eigen::VectorXd pushes_at(const NodeBacking& backing, const Eigen::VectorXd& z) {
  const auto count = static_cast<Eigen::Index>(backing.nodes.size());
  Eigen::Matrix3Xd positions(3, count), forces = Eigen::Matrix3Xd::Zero(3, count);
  for (Eigen::Index i = 0; i < count; ++i)
    positions.col(i) = backing.targets.segment<3>(3 * i) + Eigen::Vector3d(0, 0, z[i]);
  NodeBackingSolve solve;
  prepare_backing_solve(solve, backing);
  add_node_backing_forces(backing, solve, positions, Eigen::Matrix3Xd::Zero(3, count), forces);
  EXPECT_EQ(solve.failures, 0u);
  for (Eigen::Index i = 0; i < count; ++i)
    EXPECT_NEAR(forces(2, i), solve.pushes[i], 1e-12 * (1 + solve.pushes[i]));
  return forces.row(2).transpose();
}

// One free node of A's mass dropped from 1 mm above the backing's surface.
struct DroppedNode {
  MassSpringNetwork network;
  MassSpringState state;
  double highest_after_touching = -1;
  bool touched = false;
  DroppedNode() {
    network.rest_positions = Eigen::Vector3d(0.0, -0.002, 0.001);
    network.mass = Eigen::VectorXd::Constant(1, 3.7e-3);
    network.held = {0};
    network.parameters.time_step = 1e-4;
    state = make_state(network);
  }
  void run(const NodeBacking& backing, double seconds) {
    prepare_backing_solve(state.backing, backing);
    for (int i = 0; i < static_cast<int>(std::lround(seconds / 1e-4)); ++i) {
      step_network(network, state, {}, {}, 1e-4, &backing);
      touched = touched || state.positions(2, 0) < 0;
      if (touched) highest_after_touching = std::max(highest_after_touching, state.positions(2, 0));
    }
    EXPECT_EQ(state.backing.failures, 0u);
  }
};

TEST(NodeBacking, ADroppedNodeRestsAtItsWeightTimesItsComplianceWithoutABounce) {
  DroppedNode node;
  const double k = 1.5e4, m = node.network.mass[0], g = 9.81;
  node.run(one_node_backing(k, 2 * std::sqrt(k * m)), 0.5);
  EXPECT_NEAR(node.state.positions(2, 0), -m * g / k, 1e-9);  // statics: depth = A m g
  EXPECT_LT(node.state.velocities.norm(), 1e-9);
  EXPECT_LE(node.highest_after_touching,
            0);  // critically damped: it never leaves the surface again
  EXPECT_NEAR(node.state.positions(0, 0), 0.0, 1e-12);  // a normal contact: no sideways force
}

TEST(NodeBacking, AnUndampedContactGivesBackNoMoreEnergyThanItTook) {
  // Without the dashpot each bounce returns to the drop height (1 mm) up to the integrator's
  // O(h) error: the contact is the gradient of an energy, it cannot pump.
  DroppedNode node;
  node.run(one_node_backing(1.5e4, 0), 1.0);
  EXPECT_GT(node.highest_after_touching, 0.9e-3);   // it bounces ...
  EXPECT_LT(node.highest_after_touching, 1.01e-3);  // ... but no higher than it fell from
}

TEST(NodeBacking, AContactPushesOnlyWhileTheNodeIsBehindItAndNeverPulls) {
  const NodeBacking backing = one_node_backing(1e4, 20);
  NodeBackingSolve solve;
  prepare_backing_solve(solve, backing);
  Eigen::Matrix3Xd positions(3, 1), velocities = Eigen::Matrix3Xd::Zero(3, 1), forces(3, 1);
  const auto force = [&](double z, double vz) {
    positions.col(0) = Eigen::Vector3d(0.001, 0, z);
    velocities.col(0) = Eigen::Vector3d(0, 0, vz);
    forces.setZero();
    add_node_backing_forces(backing, solve, positions, velocities, forces);
    return Eigen::Vector3d(forces.col(0));
  };
  EXPECT_EQ(force(1e-4, -1.0),
            Eigen::Vector3d::Zero());            // in front of it: nothing, even approaching
  EXPECT_NEAR(force(-1e-4, 0).z(), 1.0, 1e-12);  // depth / A
  EXPECT_NEAR(force(-1e-4, -0.01).z(), 1.0 + 0.2, 1e-12);  // sinking: the dashpot adds
  EXPECT_NEAR(force(-1e-4, 0.02).z(), 1.0 - 0.4, 1e-12);   // leaving: it takes some off ...
  EXPECT_EQ(force(-1e-4, 1.0), Eigen::Vector3d::Zero());   // ... but never pulls
  EXPECT_EQ(force(-1e-4, 0).head<2>(), Eigen::Vector2d::Zero());
  EXPECT_EQ(solve.failures, 0u);
}

// Two nodes on one elastic surface: a push on either lowers the surface under the other
// (A_01 > 0). The 2x2 complementarity problem's closed form.
TEST(NodeBacking, PressingOneNodeLowersTheSurfaceUnderItsNeighbour) {
  const double a = 1e-4, b = 4e-5;  // [m/N]
  const NodeBacking backing = plane_backing((Eigen::Matrix2d() << a, b, b, a).finished(), 0);
  const double deep = 1e-3;
  // A shallow neighbour, 0.2 mm in: the deep node's push alone lowers the surface under it
  // by b deep / a = 0.4 mm, so it no longer touches and is released.
  const Eigen::VectorXd released = pushes_at(backing, Eigen::Vector2d(-deep, -0.2e-3));
  EXPECT_NEAR(released[0], deep / a, 1e-9 * deep / a);
  EXPECT_EQ(released[1],
            0);  // one spring per node (the lumped backing) would push it back by about 0.2 mm / a
  // A deeper neighbour, 0.6 mm in: both touch, A lambda = depths.
  const Eigen::Vector2d both = pushes_at(backing, Eigen::Vector2d(-deep, -0.6e-3));
  const Eigen::Vector2d expected =
      (Eigen::Matrix2d() << a, b, b, a).finished().inverse() * Eigen::Vector2d(deep, 0.6e-3);
  EXPECT_NEAR((both - expected).norm(), 0, 1e-9 * expected.norm());
  EXPECT_GT(both.minCoeff(), 0);
  // The coupling is felt: the deep node is pushed less than on its own (depth / a), as the
  // neighbour's push has lowered the surface under it too.
  EXPECT_LT(both[0], deep / a);
}

// Five nodes in a row joined by springs, dropped tilted onto an undamped coupled backing:
// they bounce, and whenever no node touches (the backing's energy then zero and the
// integrator's O(h) wobble of the contact gone) the total energy (kinetic, gravity,
// springs) is no higher than at the drop, up to the integrator's O(h) error (1 %, as for
// the single node's bounce height): the backing returned no more than it took.
TEST(NodeBacking, ANetworkDroppedOnACoupledBackingNeverGainsEnergy) {
  const int count = 5;
  MassSpringNetwork network;
  network.rest_positions = Eigen::Matrix3Xd::Zero(3, count);
  for (int i = 0; i < count; ++i)
    network.rest_positions.col(i) = Eigen::Vector3d(0.01 * i, 0, 0.5e-3 + 0.2e-3 * i);
  network.mass = Eigen::VectorXd::Constant(count, 3.7e-3);
  network.held.assign(count, 0);
  for (int i = 0; i + 1 < count; ++i) network.springs.push_back({i, i + 1, 0.01, 200, 0});
  network.parameters.time_step = 1e-4;
  // B's compliance decays with the distance between targets (an elastic half-space's 1/r).
  Eigen::MatrixXd compliance(count, count);
  for (int i = 0; i < count; ++i)
    for (int j = 0; j < count; ++j) compliance(i, j) = 1e-4 / (1 + std::abs(i - j));
  compliance.diagonal().array() +=
      1e-8 / 3.7e-3;  // the contact's own compliance (compliance_backing.h)
  const NodeBacking backing = plane_backing(compliance, 0);
  MassSpringState state = make_state(network);
  prepare_backing_solve(state.backing, backing);
  const auto free_energy = [&] {
    return kinetic_energy(network, state.velocities) + potential_energy(network, state.positions);
  };
  const double start = free_energy();
  double highest_free = -INFINITY, largest_stored = 0;
  bool touched = false;
  int free_samples = 0;
  for (int i = 0; i < 20000; ++i) {
    step_network(network, state, {}, {}, 1e-4, &backing);
    NodeBackingSolve solve = state.backing;
    Eigen::Matrix3Xd forces = Eigen::Matrix3Xd::Zero(3, count);
    add_node_backing_forces(backing, solve, state.positions, state.velocities, forces);
    const double stored = backing_energy(backing, solve.pushes);
    largest_stored = std::max(largest_stored, stored);
    touched = touched || stored > 0;
    if (touched && stored == 0) {
      highest_free = std::max(highest_free, free_energy());
      ++free_samples;
    }
  }
  EXPECT_EQ(state.backing.failures, 0u);
  const double fallen =
      network.mass.sum() * 9.81 * 0.9e-3;          // the scale of the energy exchanged [J]
  EXPECT_GT(largest_stored, 0.3 * fallen);         // the backing stored much of it ...
  EXPECT_GT(free_samples, 100);                    // ... and the network bounced off
  EXPECT_LT(highest_free - start, 1e-2 * fallen);  // no higher than it fell from, up to O(h)
  std::cout << "drop energy " << fallen << " J, stored at most " << largest_stored
            << " J, free-flight energy gain " << highest_free - start << " J\n";
}

// A client's sub-network holds the server's pushes on backed nodes outside it: with every
// node where the whole backing's solution put it, the sub-backing's pushes are the whole's.
TEST(NodeBacking, ASubNetworksBackingWithTheOthersPushesHeldGivesTheWholesPushes) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> uniform(-1, 1);
  const int count = 6;
  Eigen::MatrixXd root(count, count);
  for (Eigen::Index i = 0; i < root.size(); ++i) root.data()[i] = uniform(random);
  const Eigen::MatrixXd compliance =
      1e-5 * (root * root.transpose() + Eigen::MatrixXd::Identity(count, count));
  const NodeBacking whole = plane_backing(compliance, 0);
  Eigen::VectorXd z(count);
  for (int i = 0; i < count; ++i) z[i] = -1e-4 * (1 + uniform(random));
  const Eigen::VectorXd pushes = pushes_at(whole, z);
  ASSERT_GT((pushes.array() > 0).count(), 1);
  // The sub-network holds whole nodes 1, 3 and 4 (its local nodes 0, 1, 2).
  const std::array<std::int32_t, 3> body_nodes{1, 3, 4};
  const NodeBacking sub = sub_network_backing(whole, pushes, body_nodes);
  ASSERT_EQ(sub.nodes, (std::vector<int>{0, 1, 2}));
  const Eigen::VectorXd sub_pushes = pushes_at(sub, Eigen::Vector3d(z[1], z[3], z[4]));
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(sub_pushes[k], pushes[body_nodes[k]], 1e-9 * pushes.maxCoeff());
}

}  // namespace
}  // namespace cohaptic
