// The dense backing a condensed FEM body B gives the nodes that press on it
// (compliance_backing.h, node_backing.h), against the full sparse solve of B: each node's
// unit push, spread over its target's polygon by the barycentric weights, solved on B's
// whole stiffness (CHOLMOD, no condensation) gives B's normal compliance at the targets;
// with it the unilateral problem (B's surface under each node held at the node's
// penetration where it pushes, and released where it would have to pull) is solved by
// trying every contact set. The backing's compliance and its pushes equal that answer
// (1e-9), also where a shallow node beside a deep one is released.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <vector>

#include "common/fem/static_solve.h"
#include "common/interaction/compliance_backing.h"
#include "common/interaction/node_polygon_collision.h"
#include "support/paired_boxes.h"

namespace cohaptic {
namespace {

constexpr double kTimeStep = 1e-4;    // the front body's substep [s]
constexpr double kNodeMass = 3.7e-3;  // [kg]

// A front node at (depth behind B's near face x = 0, y, z) [m], B occupying x > 0.
struct Press {
  double depth, y, z;
};

struct Pressed {
  testing::PairedBoxesRig rig;
  std::vector<PolygonCollision> collisions;
  Eigen::Matrix3Xd positions;
  explicit Pressed(const std::vector<Press>& presses)
      : positions(3, static_cast<Eigen::Index>(presses.size())) {
    const ElasticBody& behind = rig.behind;
    for (std::size_t k = 0; k < presses.size(); ++k) {
      const Eigen::Vector3d point(presses[k].depth, presses[k].y, presses[k].z);
      positions.col(static_cast<Eigen::Index>(k)) = point;
      int nearest = -1;
      for (int node : behind.surface.nodes)
        if (nearest < 0 || (behind.mesh.nodes.col(node) - point).norm() <
                               (behind.mesh.nodes.col(nearest) - point).norm())
          nearest = node;
      const std::optional<PolygonTarget> target =
          node_polygon_collision(point, nearest, behind.mesh.nodes, rig.behind_surface);
      EXPECT_TRUE(target.has_value()) << "press " << k;
      if (!target) continue;
      PolygonCollision collision;
      collision.active = static_cast<int>(k);
      collision.polygon = rig.behind_surface.triangles[static_cast<std::size_t>(target->triangle)];
      collision.weights = target->weights;
      collision.target = target->point;
      collision.gap = point - target->point;
      collision.normal = target->normal;
      EXPECT_NEAR(collision.normal.x(), -1, 1e-12);  // B's near face
      collisions.push_back(collision);
    }
  }
};

// B's normal compliance at the targets from full sparse solves of its whole stiffness, plus
// each node's contact compliance h^2 / m.
Eigen::MatrixXd full_solve_compliance(const ElasticBody& body,
                                      const std::vector<PolygonCollision>& collisions) {
  const ConstrainedStaticSolver solver(body.stiffness, body.dofs, {});
  const auto count = static_cast<Eigen::Index>(collisions.size());
  Eigen::MatrixXd compliance(count, count);
  for (Eigen::Index j = 0; j < count; ++j) {
    const PolygonCollision& cj = collisions[static_cast<std::size_t>(j)];
    Eigen::VectorXd load = Eigen::VectorXd::Zero(3 * body.mesh.node_count());
    for (int b = 0; b < 3; ++b)
      load.segment<3>(3 * cj.polygon[b]) -= cj.weights[b] * cj.normal;  // a unit push into B
    const Eigen::VectorXd u = solver.solve(Eigen::VectorXd(0), load).displacement;
    for (Eigen::Index i = 0; i < count; ++i) {
      const PolygonCollision& ci = collisions[static_cast<std::size_t>(i)];
      Eigen::Vector3d moved = Eigen::Vector3d::Zero();
      for (int a = 0; a < 3; ++a) moved += ci.weights[a] * u.segment<3>(3 * ci.polygon[a]);
      compliance(i, j) = -ci.normal.dot(moved);  // how far target i gave way along -n_i
    }
  }
  compliance.diagonal().array() += kTimeStep * kTimeStep / kNodeMass;
  return compliance;
}

// The unilateral problem's solution by trying every contact set: the one whose pushes are
// all >= 0 and leaves every other node clear of B.
Eigen::VectorXd every_set_solution(const Eigen::MatrixXd& compliance, const Eigen::VectorXd& gaps) {
  const auto count = gaps.size();
  const double push_scale = gaps.cwiseAbs().maxCoeff() / compliance.diagonal().minCoeff();
  Eigen::VectorXd found;
  int solutions = 0;
  for (int set = 0; set < (1 << count); ++set) {
    std::vector<Eigen::Index> in;
    for (Eigen::Index i = 0; i < count; ++i)
      if (set & (1 << i)) in.push_back(i);
    const auto k = static_cast<Eigen::Index>(in.size());
    Eigen::MatrixXd block(k, k);
    Eigen::VectorXd right(k);
    for (Eigen::Index a = 0; a < k; ++a) {
      right[a] = -gaps[in[static_cast<std::size_t>(a)]];
      for (Eigen::Index b = 0; b < k; ++b)
        block(a, b) = compliance(in[static_cast<std::size_t>(a)], in[static_cast<std::size_t>(b)]);
    }
    Eigen::VectorXd pushes = Eigen::VectorXd::Zero(count);
    if (k > 0) {
      const Eigen::VectorXd solved = block.ldlt().solve(right);
      for (Eigen::Index a = 0; a < k; ++a) pushes[in[static_cast<std::size_t>(a)]] = solved[a];
    }
    const Eigen::VectorXd clearance = compliance * pushes + gaps;
    bool valid = true;
    for (Eigen::Index i = 0; i < count; ++i)
      valid =
          valid && ((set & (1 << i)) ? pushes[i] >= -1e-12 * push_scale : clearance[i] >= -1e-15);
    if (valid) {
      found = pushes;
      ++solutions;
    }
  }
  EXPECT_EQ(solutions, 1);  // positive definite: exactly one
  return found;
}

// The backing's pushes at the pressed positions (at rest), and checks against the full solve.
Eigen::VectorXd check_against_full_solve(const std::vector<Press>& presses) {
  Pressed pressed(presses);
  const auto count = static_cast<Eigen::Index>(pressed.collisions.size());
  EXPECT_EQ(count, static_cast<Eigen::Index>(presses.size()));
  const NodeBacking backing =
      compliance_backing(pressed.collisions, *pressed.rig.behind_columns,
                         Eigen::VectorXd::Constant(count, kNodeMass), kTimeStep, 1.0);
  const Eigen::MatrixXd full = full_solve_compliance(pressed.rig.behind, pressed.collisions);
  EXPECT_LE((backing.compliance - full).norm(), 1e-9 * full.norm());

  NodeBackingSolve solve;
  prepare_backing_solve(solve, backing);
  Eigen::Matrix3Xd forces = Eigen::Matrix3Xd::Zero(3, count);
  add_node_backing_forces(backing, solve, pressed.positions, Eigen::Matrix3Xd::Zero(3, count),
                          forces);
  EXPECT_EQ(solve.failures, 0u);
  Eigen::VectorXd gaps(count);
  for (Eigen::Index i = 0; i < count; ++i) {
    const PolygonCollision& collision = pressed.collisions[static_cast<std::size_t>(i)];
    gaps[i] = collision.gap.dot(collision.normal);
  }
  const Eigen::VectorXd expected = every_set_solution(full, gaps);
  EXPECT_LE((solve.pushes - expected).cwiseAbs().maxCoeff(), 1e-9 * expected.cwiseAbs().maxCoeff());
  for (Eigen::Index i = 0; i < count; ++i)
    EXPECT_LE((forces.col(i) - expected[i] * pressed.collisions[static_cast<std::size_t>(i)].normal)
                  .norm(),
              1e-9 * expected.cwiseAbs().maxCoeff());
  return expected;
}

TEST(ComplianceBacking, ThreeNeighboursPressingTogetherGetTheFullSolvesPushes) {
  const Eigen::VectorXd pushes = check_against_full_solve(
      {{0.5e-3, 0.060, 0.050}, {0.45e-3, 0.070, 0.055}, {0.5e-3, 0.065, 0.045}});
  EXPECT_GE((pushes.array() > 0).count(), 2);
}

TEST(ComplianceBacking, AShallowNodeBesideADeepOneIsReleasedAsInTheFullSolve) {
  // The shallow node penetrates B's rest surface, but the deep one's push lowers B's surface
  // under it further than that: B would have to pull it.
  const Eigen::VectorXd pushes =
      check_against_full_solve({{1.0e-3, 0.065, 0.054}, {0.05e-3, 0.075, 0.054}});
  EXPECT_GT(pushes[0], 0);
  EXPECT_EQ(pushes[1], 0);
}

TEST(ComplianceBacking, FiveNodesSpreadOverTheFaceGetTheFullSolvesPushes) {
  const Eigen::VectorXd pushes = check_against_full_solve({{0.8e-3, 0.030, 0.030},
                                                           {0.1e-3, 0.040, 0.035},
                                                           {0.6e-3, 0.070, 0.080},
                                                           {0.2e-3, 0.100, 0.060},
                                                           {0.4e-3, 0.090, 0.040}});
  EXPECT_GT((pushes.array() > 0).count(), 2);
}

}  // namespace
}  // namespace cohaptic
