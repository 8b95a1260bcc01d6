// The independent answer for FEM against FEM (common/sim/fem_pair_coupling.h): one sparse
// solve of A and B together, for the tests. Unknowns: A's free dofs but the held ones, B's
// free dofs, and one Lagrange multiplier (a push) per collision of the contact set, each
// pushing collision's gap zero; Eigen's SparseLU on the saddle-point system, no compliance
// columns and no CHOLMOD. Its own active-set loop finds the set: start from the penetrating
// candidates, drop pulling ones, add penetrating ones, until none moves. Gaps are measured
// as the collisions measure them (normal offset from the polygon's plane). Units: m, N.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/interaction/forcible_displacement.h"
#include "common/model/elastic_body.h"

namespace cohaptic::testing {

struct JointPairSolution {
  Eigen::VectorXd pushes;         ///< per collision, zero outside the set [N]
  Eigen::VectorXd gaps;           ///< per collision [m]
  Eigen::VectorXd front, behind;  ///< displacements, 3 per node of each body [m]
  Eigen::VectorXd
      front_reaction;  ///< K_A u_A, 3 per node of A: the forces holding A's held dofs [N]
};

/// A with `held_dofs` (global free dofs) at `held_values` [m], against B through `collisions`.
JointPairSolution joint_pair_solve(const ElasticBody& front, const ElasticBody& behind,
                                   std::span<const int> held_dofs,
                                   const Eigen::VectorXd& held_values,
                                   const std::vector<PolygonCollision>& collisions);

}  // namespace cohaptic::testing
