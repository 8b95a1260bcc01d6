// The backing a body behind a mass-spring network gives its nodes (node_backing.h,
// linear_backing.h): one normal contact spring-damper per node. Checked against independent
// answers: a dropped node comes to rest at its weight over the stiffness (statics) without
// ever gaining energy (a contact that pumped energy let the paired boxes' front object bounce
// off and fall through); a contact never pulls; the lumped stiffness gives, for a uniform
// sinking of every backed node, each node's normal force of the dense condensed stiffness.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "common/interaction/linear_backing.h"
#include "common/mass_spring/integrate_network.h"
#include "common/mass_spring/node_backing.h"

namespace cohaptic {
namespace {

NodeBacking one_node_backing(double stiffness, double damping) {
  return {{0}, Eigen::VectorXd::Constant(1, stiffness), Eigen::VectorXd::Constant(1, damping), Eigen::VectorXd::Zero(3),
          Eigen::Vector3d::UnitZ()};
}

// One free node of A's mass dropped from 1 mm above the backing's surface.
struct DroppedNode {
  MassSpringNetwork network;
  MassSpringState state;
  double highest_after_touching = -1;
  bool touched = false;
  DroppedNode() {
    network.rest_positions = Eigen::Vector3d(0.003, -0.002, 0.001);
    network.mass = Eigen::VectorXd::Constant(1, 3.7e-3);
    network.held = {0};
    network.parameters.time_step = 1e-4;
    state = make_state(network);
  }
  void run(const NodeBacking& backing, double seconds) {
    for (int i = 0; i < static_cast<int>(std::lround(seconds / 1e-4)); ++i) {
      step_network(network, state, {}, {}, 1e-4, &backing);
      touched = touched || state.positions(2, 0) < 0;
      if (touched) highest_after_touching = std::max(highest_after_touching, state.positions(2, 0));
    }
  }
};

TEST(NodeBacking, ADroppedNodeRestsAtItsWeightOverTheStiffnessWithoutABounce) {
  DroppedNode node;
  const double k = 1.5e4, m = node.network.mass[0], g = 9.81;
  node.run(one_node_backing(k, 2 * std::sqrt(k * m)), 0.5);
  EXPECT_NEAR(node.state.positions(2, 0), -m * g / k, 1e-9);  // statics: k depth = m g
  EXPECT_LT(node.state.velocities.norm(), 1e-9);
  EXPECT_LE(node.highest_after_touching, 0);  // critically damped: it never leaves the surface again
  EXPECT_NEAR(node.state.positions(0, 0), 0.003, 1e-12);  // a normal contact: no sideways force
}

TEST(NodeBacking, AnUndampedContactGivesBackNoMoreEnergyThanItTook) {
  // Without the dashpot each bounce returns to the drop height (1 mm) up to the integrator's
  // O(h) error: the contact is the gradient of an energy, it cannot pump.
  DroppedNode node;
  node.run(one_node_backing(1.5e4, 0), 1.0);
  EXPECT_GT(node.highest_after_touching, 0.9e-3);  // it bounces ...
  EXPECT_LT(node.highest_after_touching, 1.01e-3);  // ... but no higher than it fell from
}

TEST(NodeBacking, AContactPushesOnlyWhileTheNodeIsBehindItAndNeverPulls) {
  const NodeBacking backing = one_node_backing(1e4, 20);
  Eigen::Matrix3Xd positions(3, 1), velocities = Eigen::Matrix3Xd::Zero(3, 1), forces(3, 1);
  const auto force = [&](double z, double vz) {
    positions.col(0) = Eigen::Vector3d(0.001, 0, z);
    velocities.col(0) = Eigen::Vector3d(0, 0, vz);
    forces.setZero();
    add_node_backing_forces(backing, positions, velocities, forces);
    return Eigen::Vector3d(forces.col(0));
  };
  EXPECT_EQ(force(1e-4, -1.0), Eigen::Vector3d::Zero());        // in front of it: nothing, even approaching
  EXPECT_NEAR(force(-1e-4, 0).z(), 1.0, 1e-12);                 // k depth
  EXPECT_NEAR(force(-1e-4, -0.01).z(), 1.0 + 0.2, 1e-12);       // sinking: the dashpot adds
  EXPECT_NEAR(force(-1e-4, 0.02).z(), 1.0 - 0.4, 1e-12);        // leaving: it takes some off ...
  EXPECT_EQ(force(-1e-4, 1.0), Eigen::Vector3d::Zero());        // ... but never pulls
  EXPECT_EQ(force(-1e-4, 0).head<2>(), Eigen::Vector2d::Zero());
}

TEST(NodeBacking, LumpedStiffnessGivesTheDenseBackingsNormalForcesForAUniformSinking) {
  // A dense backing K (symmetric positive definite) over four nodes on tilted normals.
  std::mt19937 random(11);
  std::uniform_real_distribution<double> uniform(-1, 1);
  const int count = 4;
  Eigen::MatrixXd root(3 * count, 3 * count);
  for (Eigen::Index i = 0; i < root.size(); ++i) root.data()[i] = uniform(random);
  LinearBacking dense;
  dense.stiffness = 1e3 * (root * root.transpose() + 3 * count * Eigen::MatrixXd::Identity(3 * count, 3 * count));
  dense.contact_displacement = Eigen::VectorXd::Zero(3 * count);
  std::vector<PolygonCollision> collisions(count);
  Eigen::Matrix3Xd rest = Eigen::Matrix3Xd::Zero(3, count);
  for (int i = 0; i < count; ++i) {
    dense.nodes.push_back(i);
    collisions[static_cast<std::size_t>(i)].active = i;
    collisions[static_cast<std::size_t>(i)].target = Eigen::Vector3d(0.01 * i, 0, 0);
    collisions[static_cast<std::size_t>(i)].normal = Eigen::Vector3d(0.1 * uniform(random), 0.1 * uniform(random), 1).normalized();
    rest.col(i) = collisions[static_cast<std::size_t>(i)].target;
    dense.contact_displacement.segment<3>(3 * i) = collisions[static_cast<std::size_t>(i)].target - rest.col(i);
  }
  const NodeBacking lumped = node_backing(dense, collisions, Eigen::VectorXd::Constant(count, 3.7e-3), 1.0);
  const double depth = 2e-5;
  Eigen::VectorXd sunk(3 * count);
  Eigen::Matrix3Xd positions(3, count);
  for (int i = 0; i < count; ++i) {
    sunk.segment<3>(3 * i) = -depth * collisions[static_cast<std::size_t>(i)].normal;
    positions.col(i) = rest.col(i) + sunk.segment<3>(3 * i);
  }
  Eigen::VectorXd dense_force(3 * count);
  evaluate_linear_backing(dense, sunk, dense_force);
  Eigen::Matrix3Xd forces = Eigen::Matrix3Xd::Zero(3, count);
  add_node_backing_forces(lumped, positions, Eigen::Matrix3Xd::Zero(3, count), forces);
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d& normal = collisions[static_cast<std::size_t>(i)].normal;
    EXPECT_GT(lumped.stiffness[i], 0);
    EXPECT_NEAR(forces.col(i).dot(normal), dense_force.segment<3>(3 * i).dot(normal),
                1e-9 * std::abs(dense_force.segment<3>(3 * i).dot(normal)));
    EXPECT_NEAR(lumped.damping[i], 2 * std::sqrt(lumped.stiffness[i] * 3.7e-3), 1e-12);
  }
}

}  // namespace
}  // namespace cohaptic
