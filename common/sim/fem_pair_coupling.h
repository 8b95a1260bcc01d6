// FEM against FEM: a linear elastic front body A pressing on a linear
// elastic body B behind it, both condensed through their compliance columns.
//
// Contact: the collisions' active nodes P of A against B's rest surface, each at a target
// on a polygon of B (barycentric weights w_i, outward normal n_i). A push lambda_i >= 0
// along n_i loads A at its node by +n_i lambda_i and B at the polygon's nodes by
// -w_ia n_i lambda_i. Both bodies are linear about rest and the polygons stay where they
// are for the solve, so the gaps along the normals under the pushes are
//   g = (A_A + A_B) lambda + g_free,
// with A_A = N^T L'_PP N A's normal compliance at P while its held dofs H (the tools'
// nodes) stay held, L' = L_PP - L_PH L_HH^-1 L_HP; A_B B's normal compliance at the
// targets (target_normal_compliance); g_free the gaps at A's state without B. The
// unilateral problem g >= 0, lambda >= 0, lambda_i g_i = 0 is solved by
// solve_unilateral_contact (one solution for a positive definite A_A + A_B). No contact
// compliance is added: a static solve has no explicit integrator to keep stable, so the
// answer is both bodies' linear elasticity, exactly.
// The pushes change the forces holding A at H by -L_HH^-1 L_HP N lambda (a tool pressing A
// towards B feels B) and displace B by u_B = -L_B W N lambda.
//
// The IR's form: while the set S of pushing nodes stays the same, B is an elastic support
// of A's nodes S (supported_compliance.h, with A_B,SS), and A's M~ condensed over it feels B.
// Units: m, N, m/N. Allocates (server side, not the haptic path).
#pragma once

#include <Eigen/Core>
#include <span>

#include "common/fem/compliance.h"
#include "common/interaction/forcible_displacement.h"

namespace cohaptic {

struct FemPairContact {
  bool solved = false;               ///< false: A_A + A_B not positive definite (nothing gives way)
  Eigen::MatrixXd front_compliance;  ///< A_A, |collisions| square [m/N]
  Eigen::MatrixXd behind_compliance;  ///< A_B, |collisions| square [m/N]
  Eigen::VectorXd free_gaps;          ///< g_free = gap . n per collision [m]
  Eigen::VectorXd pushes;             ///< lambda per collision [N], zero where released
  Eigen::VectorXd gaps;               ///< g under the pushes [m], zero where pushed
  Eigen::VectorXd held_force_change;  ///< per held dof of A: change of the force holding it [N]
};

/// The coupled contact of `collisions` (active: A's nodes, found at A's state without B;
/// polygons: B's). `front_held_dofs` are free global dofs of A held where they are (the
/// tools'); A's row nodes must include them and the active nodes, B's the polygon nodes.
FemPairContact solve_fem_pair_contact(std::span<const PolygonCollision> collisions,
                                      ComplianceColumns& front_columns,
                                      std::span<const int> front_held_dofs,
                                      ComplianceColumns& behind_columns);

/// B's displacement under the pushes, u_B = -L_B W N lambda, 3 per row node of
/// `behind_columns` [m].
Eigen::VectorXd behind_pair_displacement(std::span<const PolygonCollision> collisions,
                                         const Eigen::Ref<const Eigen::VectorXd>& pushes,
                                         ComplianceColumns& behind_columns);

}  // namespace cohaptic
