// The several-objects paper's pushing test (Sec. 3.2) on its two boxes, quasi-statically:
// the front object A (springs along its tetrahedra's edges) pushed 1-15 mm with its back
// free, fixed or resting on the linear FEM box B. Checked against:
//   - the paper's ordering F_free < F_on-B < F_fixed at every depth, and its limits: a very
//     stiff B gives the fixed force (1 %), a very soft one the free force (1 %);
//   - B's share: its condensed stiffness on the displaced nodes scales exactly with E_B
//     (1e-9), and the force at 15 mm rises strictly with E_B and falls strictly with nu_B;
//   - an independent solve of both bodies: B's full sparse solve (CHOLMOD) with the
//     displaced nodes prescribed, its reactions conveyed to A, and A's spring forces summed
//     spring by spring, balance at every free dof of A but the held tool node's and give the
//     tool's force (1e-9);
//     A's back nodes lie on B's displaced polygons (1e-9 m); no kept contact pulls.
#include <gtest/gtest.h>

#include "common/interaction/condensed_response.h"
#include "common/interaction/push_conditions.h"
#include "lab/objects_push.h"
#include "common/scene/load_scene.h"
#include "support/prescribed_nodes_solve.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

// scenes/objects/push.yaml: the paper's A as a lattice object in front of its B.
const Scene& push_test_scene() {
  static const Scene scene = load_scene(testing::source_path("scenes/objects/push.yaml"));
  return scene;
}

PushRig with_behind(double youngs_modulus, double poisson_ratio = 0.216) {
  return PushRig(push_test_scene(), {BackCondition::on_behind, youngs_modulus, poisson_ratio});
}

TEST(InteractionPush, FreeBelowOnBehindBelowFixedAtEveryDepth) {
  PushRig rig = with_behind(1.0e6);
  EXPECT_EQ(rig.front.rest_positions.cols(), 60);
  EXPECT_EQ(rig.behind().mesh.node_count(), 1950);
  const std::vector<double> depths = paper_push_depths();
  const std::vector<double> free = push_forces(rig, BackCondition::free, depths);
  const std::vector<double> on_behind = push_forces(rig, BackCondition::on_behind, depths);
  const std::vector<double> fixed = push_forces(rig, BackCondition::fixed, depths);
  for (std::size_t i = 0; i < depths.size(); ++i) {
    EXPECT_GT(free[i], 0) << depths[i];
    EXPECT_LT(free[i], on_behind[i]) << depths[i];
    EXPECT_LT(on_behind[i], fixed[i]) << depths[i];
  }
}

TEST(InteractionPush, StiffBehindGivesTheFixedForceSoftBehindTheFree) {
  const std::vector<double> depth{0.015};
  PushRig stiff = with_behind(1e12), soft = with_behind(1);
  const double fixed = push_forces(stiff, BackCondition::fixed, depth)[0];
  const double free = push_forces(stiff, BackCondition::free, depth)[0];
  EXPECT_NEAR(push_forces(stiff, BackCondition::on_behind, depth)[0], fixed, 0.01 * fixed);
  EXPECT_NEAR(push_forces(soft, BackCondition::on_behind, depth)[0], free, 0.01 * free);
  EXPECT_GT(fixed, 1.05 * free);  // the limits are apart, so the two checks say something
}

TEST(InteractionPush, BehindShareScalesWithYoungsModulusAndTheForceIsMonotoneInEAndNu) {
  const std::vector<double> depth{0.015};
  PushRig base = with_behind(1.0e6), doubled = with_behind(2.0e6);
  BehindBody behind = base.behind_body();
  const PushSample sample = push_front(base.front, BackCondition::on_behind, &behind, depth)[0];
  ASSERT_FALSE(sample.forcible.nodes.empty());
  const Eigen::MatrixXd k1 =
      condensed_stiffness(*base.behind_columns, base.behind().dofs, sample.forcible.nodes);
  const Eigen::MatrixXd k2 =
      condensed_stiffness(*doubled.behind_columns, doubled.behind().dofs, sample.forcible.nodes);
  EXPECT_LT((k2 - 2 * k1).norm(), 1e-9 * k2.norm());

  double previous = 0;
  for (double e : {1.0e6, 1.5e6, 2.0e6}) {
    PushRig rig = with_behind(e);
    const double force = push_forces(rig, BackCondition::on_behind, depth)[0];
    EXPECT_GT(force, previous) << "E_B " << e;
    previous = force;
  }
  // With E_B held, a larger nu_B lowers B's shear modulus E / 2(1 + nu): the force falls.
  previous = INFINITY;
  for (double nu : {0.108, 0.162, 0.216}) {
    PushRig rig = with_behind(1.0e6, nu);
    const double force = push_forces(rig, BackCondition::on_behind, depth)[0];
    EXPECT_LT(force, previous) << "nu_B " << nu;
    previous = force;
  }
}

// K_A u summed spring by spring (k n n^T (u_a - u_b) on a), independent of network_stiffness.
Eigen::VectorXd spring_forces(const PushedFront& front, const Eigen::VectorXd& u) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(u.size());
  for (const Spring& s : front.springs) {
    const Eigen::Vector3d n =
        (front.rest_positions.col(s.b) - front.rest_positions.col(s.a)).normalized();
    const Eigen::Vector3d on_a =
        s.stiffness * n * n.dot(u.segment<3>(3 * s.a) - u.segment<3>(3 * s.b));
    f.segment<3>(3 * s.a) += on_a;
    f.segment<3>(3 * s.b) -= on_a;
  }
  return f;
}

TEST(InteractionPush, OnBehindBalancesAgainstTheFullSparseSolveOfB) {
  for (const auto& [depth, e] : {std::pair{0.004, 1.0e6}, std::pair{0.015, 1.5e6}}) {
    PushRig rig = with_behind(e);
    BehindBody behind = rig.behind_body();
    const std::vector<double> depths{depth};
    const PushSample sample = push_front(rig.front, BackCondition::on_behind, &behind, depths)[0];
    ASSERT_GE(sample.collisions.size(), 4u);
    // The gaps of A's back nodes, B's displaced nodes, B's full solve.
    const auto collided = static_cast<Eigen::Index>(3 * sample.collisions.size());
    Eigen::VectorXd gaps(collided);
    for (std::size_t k = 0; k < sample.collisions.size(); ++k) {
      const PolygonCollision& c = sample.collisions[k];
      gaps.segment<3>(3 * static_cast<Eigen::Index>(k)) =
          rig.front.rest_positions.col(c.active) + sample.displacement.segment<3>(3 * c.active) -
          c.target;
    }
    const ElasticBody& b = rig.behind();
    const StaticSolution solution =
        testing::prescribed_nodes_solve(b, sample.forcible.nodes, sample.forcible.map * gaps);
    const Eigen::VectorXd conveyed =
        -sample.forcible.map.transpose() *
        testing::free_reactions(b, solution.reaction, sample.forcible.nodes);

    // A's balance: spring forces = B's conveyed reaction at every free dof but the tool's.
    Eigen::VectorXd residual = spring_forces(rig.front, sample.displacement);
    for (std::size_t k = 0; k < sample.collisions.size(); ++k) {
      residual.segment<3>(3 * sample.collisions[k].active) -=
          conveyed.segment<3>(3 * static_cast<Eigen::Index>(k));
      // No kept contact pulls A into B.
      EXPECT_GE(
          conveyed.segment<3>(3 * static_cast<Eigen::Index>(k)).dot(sample.collisions[k].normal),
          0);
    }
    const int tool_dof = 3 * rig.front.tool_node + rig.front.push_axis;
    EXPECT_NEAR(residual[tool_dof], sample.force, 1e-9 * sample.force);
    for (int dof = 0; dof < residual.size(); ++dof) {
      const bool fixed =
          (rig.front.fixed_axes[static_cast<std::size_t>(dof / 3)] >> (dof % 3)) & 1u;
      if (dof / 3 != rig.front.tool_node && !fixed) {  // the tool holds its node on every axis
        EXPECT_NEAR(residual[dof], 0, 1e-9 * sample.force) << "dof " << dof;
      }
    }

    // Each back node on its polygon as B's full solve displaced it.
    for (const PolygonCollision& c : sample.collisions) {
      Eigen::Vector3d on_polygon = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < 3; ++k)
        on_polygon +=
            c.weights[static_cast<Eigen::Index>(k)] *
            (b.mesh.nodes.col(c.polygon[k]) + solution.displacement.segment<3>(3 * c.polygon[k]));
      EXPECT_LT((on_polygon - rig.front.rest_positions.col(c.active) -
                 sample.displacement.segment<3>(3 * c.active))
                    .norm(),
                1e-9)
          << "back node " << c.active;
    }
  }
}

}  // namespace
}  // namespace cohaptic
