// The backing (node_backing.h) a condensed linear elastic body B gives the front body's
// nodes that collide with it, or may before the next step: B's normal compliance at the
// nodes' target points,
//   A_ij = n_i^T (sum_a sum_b w_ia w_jb L_ab) n_j + delta_ij h^2 / m_i,
// with w the targets' barycentric weights over their polygons' nodes a, b, L B's compliance
// between those nodes (ComplianceColumns; zero on fixed axes) and n the polygons' outward
// normals. The first term is exact linear elasticity: a push lambda_j on node j's target,
// spread to its polygon's nodes by the same weights, moves target i along n_i by A_ij
// lambda_j. The second is each node's own contact compliance, the stiffest contact that the
// front body's explicit substep h (its time step) integrates stably for the node's mass m_i
// (omega h = 1): it keeps A positive definite where B cannot give way (a fixed polygon, two
// targets at one point) and bounds the coupled stiffness for the integrator (A^-1 <= M/h^2).
// Why a compliance rather than the stiffness map^T K_cc map of the forcible displacement
// (linear_backing.h): it is B's energy minimised over every surface displacement that
// meets the contacts, defined for any set of targets, and the form the unilateral solve
// needs. Each node's dashpot is c_i = 2 damping_ratio sqrt(m_i / A_ii) (critical on the
// node's own contact). Units: m, N, m/N, kg, s.
#pragma once

#include <Eigen/Core>
#include <span>

#include "common/fem/compliance.h"
#include "common/interaction/forcible_displacement.h"
#include "common/mass_spring/node_backing.h"

namespace cohaptic {

/// B's normal compliance at the targets of `collisions` (the first term above, without the
/// contact compliance), |collisions| square and exactly symmetric; `columns` are B's, their
/// row nodes including every polygon node.
Eigen::MatrixXd target_normal_compliance(std::span<const PolygonCollision> collisions,
                                         ComplianceColumns& columns);

/// The backing of `collisions` (targets on B's rest surface, active nodes of the front
/// body whose node masses are `masses`); `columns` are B's, their row nodes including every
/// polygon node; `time_step` the front body's substep [s] > 0.
NodeBacking compliance_backing(std::span<const PolygonCollision> collisions,
                               ComplianceColumns& columns,
                               const Eigen::Ref<const Eigen::VectorXd>& masses, double time_step,
                               double damping_ratio);

}  // namespace cohaptic
