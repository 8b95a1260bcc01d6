// The interaction of a front FEM body pressed into a condensed FEM body behind it (the
// several-objects paper's two boxes, coarse): pairs grown from one by the neighbours of
// colliding nodes reach every node that penetrates (brute force) and each pair's passive
// node is the nearest surface node (brute force); B's reaction and deformation equal the
// full sparse solve with the displaced nodes prescribed (1e-9); every active node lies
// on its displaced polygon, read from B's deformation (1e-9 m); the naive workflow equals
// the improved one (1e-12); the linear backing equals the full solve's conveyed reaction
// for other displacements of the colliding nodes (1e-9); no kept collision pulls, and
// the nodes released for pulling lie outside B as it deformed.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "common/fem/static_solve.h"
#include "common/interaction/interaction_step.h"
#include "common/interaction/linear_backing.h"
#include "support/paired_boxes.h"
#include "support/prescribed_nodes_solve.h"

namespace cohaptic {
namespace {

double relative_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  EXPECT_EQ(a.size(), b.size());
  if (a.size() != b.size()) return INFINITY;
  return (a - b).norm() / std::max(b.norm(), 1e-300);
}

// A's face towards B pushed by a round bump of `depth` [m] (radius 30 mm) into B.
Eigen::Matrix3Xd pushed_front(const testing::PairedBoxesRig& rig, double depth) {
  Eigen::Matrix3Xd positions = rig.front.mesh.nodes;
  const Eigen::Vector2d centre(0.0654, 0.035);
  for (int node : rig.front_face) {
    const double r2 = (positions.col(node).tail<2>() - centre).squaredNorm() / (0.03 * 0.03);
    positions(0, node) += depth * std::max(0.0, 1 - r2);
  }
  return positions;
}

struct Pushed {
  testing::PairedBoxesRig rig;
  Eigen::Matrix3Xd front_positions;
  NodePairList pairs;
  CondensedResponseWorkspace workspace;
  InteractingBodies bodies() {
    return {front_positions,    rig.front_surface, rig.behind.mesh.nodes,
            rig.behind_surface, rig.behind.dofs,   *rig.behind_columns};
  }
  // One pair to start with (the face node nearest the bump's centre), then steps until no
  // pair is added; returns the last step.
  InteractionStep settle(InteractionWorkflow workflow = InteractionWorkflow::improved) {
    InteractionStep step;
    for (int steps = 0; steps < 50; ++steps) {
      step = interaction_step(pairs, bodies(), workflow, workspace);
      if (step.pairs_added == 0) return step;
    }
    ADD_FAILURE() << "pairs still growing after 50 steps";
    return step;
  }
  explicit Pushed(double depth) : Pushed(pushed_front(testing::PairedBoxesRig(), depth)) {}
  explicit Pushed(Eigen::Matrix3Xd positions) : front_positions(std::move(positions)) {
    int deepest = rig.front_face.front();
    for (int node : rig.front_face)
      if (front_positions(0, node) > front_positions(0, deepest)) deepest = node;
    pairs = make_node_pairs(std::span(&deepest, 1), front_positions, rig.behind.surface.nodes,
                            rig.behind.mesh.nodes);
  }
};

using testing::free_reactions;
using testing::nodal;
using testing::prescribed_nodes_solve;

TEST(InteractionFem, PairsGrownFromOneReachEveryPenetratingNodeAndAreNearest) {
  Pushed pushed(0.006);
  const InteractionStep step = pushed.settle();
  std::vector<int> colliding, penetrating;
  for (const NodePair& pair : pushed.pairs.pairs)
    if (node_polygon_collision(pushed.front_positions.col(pair.active), pair.passive,
                               pushed.rig.behind.mesh.nodes, pushed.rig.behind_surface))
      colliding.push_back(pair.active);
  EXPECT_EQ(colliding.size(), step.collisions.size() + static_cast<std::size_t>(step.released));
  for (int node : pushed.rig.front_face)
    if (pushed.front_positions(0, node) > 0) penetrating.push_back(node);
  std::sort(colliding.begin(), colliding.end());
  EXPECT_GT(penetrating.size(), 4u);
  EXPECT_EQ(colliding, penetrating);
  for (const NodePair& pair : pushed.pairs.pairs) {
    double nearest = INFINITY;
    for (int node : pushed.rig.behind.surface.nodes)
      nearest = std::min(nearest, (pushed.rig.behind.mesh.nodes.col(node) -
                                   pushed.front_positions.col(pair.active))
                                      .norm());
    EXPECT_NEAR(
        (pushed.rig.behind.mesh.nodes.col(pair.passive) - pushed.front_positions.col(pair.active))
            .norm(),
        nearest, 1e-15);
  }
}

TEST(InteractionFem,
     ReactionAndDeformationEqualTheFullSparseSolveAndActiveNodesLieOnDisplacedPolygons) {
  Pushed pushed(0.006);
  const InteractionStep step = pushed.settle();
  ASSERT_FALSE(step.collisions.empty());
  const ElasticBody& behind = pushed.rig.behind;
  const StaticSolution solution =
      prescribed_nodes_solve(behind, step.displacement.nodes, step.displacement.displacement);
  EXPECT_LT(relative_difference(step.passive_forces,
                                free_reactions(behind, solution.reaction, step.displacement.nodes)),
            1e-9);
  EXPECT_LT(relative_difference(step.passive_deformation,
                                nodal(solution.displacement, behind.surface.nodes)),
            1e-9);
  // B pushes A back, out of B (towards -x).
  double push_back = 0;
  for (Eigen::Index k = 0; k < step.active_forces.size(); k += 3)
    push_back += step.active_forces[k];
  EXPECT_LT(push_back, 0);

  // Each active node on its polygon displaced as B's deformation says.
  for (const PolygonCollision& c : step.collisions) {
    Eigen::Vector3d on_polygon = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < 3; ++k) {
      const int node = c.polygon[k];
      const int row = pushed.rig.behind_columns->row_position(node);
      on_polygon += c.weights[static_cast<Eigen::Index>(k)] *
                    (behind.mesh.nodes.col(node) + step.passive_deformation.segment<3>(3 * row));
    }
    EXPECT_LT((on_polygon - pushed.front_positions.col(c.active)).norm(), 1e-9)
        << "active node " << c.active;
  }
}

TEST(InteractionFem, NaiveWorkflowEqualsImproved) {
  Pushed improved(0.006), naive(0.006);
  const InteractionStep a = improved.settle(InteractionWorkflow::improved);
  const InteractionStep b = naive.settle(InteractionWorkflow::naive);
  ASSERT_EQ(a.collisions.size(), b.collisions.size());
  EXPECT_GE(a.collisions.size(), 3u);
  EXPECT_EQ(a.released, b.released);
  EXPECT_EQ(a.displacement.nodes, b.displacement.nodes);
  EXPECT_LT(relative_difference(b.active_forces, a.active_forces), 1e-12);
  EXPECT_LT(relative_difference(b.passive_forces, a.passive_forces), 1e-12);
  EXPECT_LT(relative_difference(b.passive_deformation, a.passive_deformation), 1e-12);
}

TEST(InteractionFem, LinearBackingEqualsTheFullSolveForOtherDisplacementsOfTheCollidingNodes) {
  Pushed pushed(0.006);
  const InteractionStep step = pushed.settle();
  const ElasticBody& behind = pushed.rig.behind;
  const Eigen::MatrixXd stiffness =
      condensed_stiffness(*pushed.rig.behind_columns, behind.dofs, step.displacement.nodes);
  const LinearBacking backing = build_linear_backing(step.collisions, step.displacement, stiffness,
                                                     pushed.rig.front.mesh.nodes);
  const auto size = static_cast<Eigen::Index>(3 * backing.nodes.size());
  // At the step's own displacement: the conveyed reaction.
  Eigen::VectorXd displacement(size), force(size);
  for (std::size_t k = 0; k < backing.nodes.size(); ++k)
    displacement.segment<3>(3 * static_cast<Eigen::Index>(k)) =
        pushed.front_positions.col(backing.nodes[k]) -
        pushed.rig.front.mesh.nodes.col(backing.nodes[k]);
  evaluate_linear_backing(backing, displacement, force);
  EXPECT_LT(relative_difference(force, step.active_forces), 1e-9);
  // Elsewhere, pairs and polygons held: the full solve for the displaced nodes that map
  // gives, conveyed back.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.0005, 0.0005);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd moved = displacement;
    for (Eigen::Index i = 0; i < size; ++i) moved[i] += jitter(rng);
    Eigen::VectorXd gaps(size);
    for (std::size_t k = 0; k < backing.nodes.size(); ++k) {
      const auto at = 3 * static_cast<Eigen::Index>(k);
      gaps.segment<3>(at) = pushed.rig.front.mesh.nodes.col(backing.nodes[k]) +
                            moved.segment<3>(at) - step.collisions[k].target;
    }
    const Eigen::VectorXd passive_displacement = step.displacement.map * gaps;
    const StaticSolution solution =
        prescribed_nodes_solve(behind, step.displacement.nodes, passive_displacement);
    const Eigen::VectorXd expected =
        -step.displacement.map.transpose() *
        free_reactions(behind, solution.reaction, step.displacement.nodes);
    evaluate_linear_backing(backing, moved, force);
    EXPECT_LT(relative_difference(force, expected), 1e-9) << "trial " << trial;
  }
}

TEST(InteractionFem, NoKeptCollisionPullsAndReleasedNodesLieOutsideTheDeformedBody) {
  // One node of A's face deep in B and its neighbours on the face barely in: B sinks
  // under them further than they press.
  const testing::PairedBoxesRig shape;
  Eigen::Matrix3Xd positions = shape.front.mesh.nodes;
  const Eigen::Vector3d centre(0, 0.0654, 0.035);
  int deepest = shape.front_face.front();
  for (int node : shape.front_face)
    if ((positions.col(node) - centre).tail<2>().norm() <
        (positions.col(deepest) - centre).tail<2>().norm())
      deepest = node;
  for (int node : shape.front_surface.neighbours(deepest))
    if (positions(0, node) > -0.0011) positions(0, node) = 0.0001;
  positions(0, deepest) = 0.01;
  Pushed pushed(std::move(positions));
  const InteractionStep step = pushed.settle();
  ASSERT_FALSE(step.collisions.empty());
  EXPECT_GT(step.released, 0);
  for (std::size_t k = 0; k < step.collisions.size(); ++k)
    EXPECT_GE(step.active_forces.segment<3>(3 * static_cast<Eigen::Index>(k))
                  .dot(step.collisions[k].normal),
              0);
  // Each released node (penetrating at rest, not kept) is in front of the polygon it hit,
  // as B's deformation moved that polygon.
  std::vector<int> kept;
  for (const PolygonCollision& c : step.collisions) kept.push_back(c.active);
  const testing::PairedBoxesRig& rig = pushed.rig;
  int released = 0;
  for (const NodePair& pair : pushed.pairs.pairs) {
    if (std::find(kept.begin(), kept.end(), pair.active) != kept.end()) continue;
    const Eigen::Vector3d active = pushed.front_positions.col(pair.active);
    const auto target =
        node_polygon_collision(active, pair.passive, rig.behind.mesh.nodes, rig.behind_surface);
    if (!target) continue;
    ++released;
    const Triangle& polygon =
        rig.behind_surface.triangles[static_cast<std::size_t>(target->triangle)];
    Eigen::Matrix3d moved;
    for (std::size_t k = 0; k < 3; ++k)
      moved.col(static_cast<Eigen::Index>(k)) =
          rig.behind.mesh.nodes.col(polygon[k]) +
          step.passive_deformation.segment<3>(3 * rig.behind_columns->row_position(polygon[k]));
    const Eigen::Vector3d normal =
        (moved.col(1) - moved.col(0)).cross(moved.col(2) - moved.col(0)).normalized();
    EXPECT_GT((active - moved.col(0)).dot(normal), -1e-9) << "released node " << pair.active;
  }
  EXPECT_EQ(released, step.released);
}

}  // namespace
}  // namespace cohaptic
