// LinearBacking: the behind body felt through the front body's colliding nodes, as a
// linear map that an IR body can carry while the pairs and their polygons stay the same.
//
// The displaced passive nodes move by u_c = map * (gaps) and the gap of each colliding
// active node is u - u*, with u its displacement from rest and u* = T - X its displacement
// at which it just touches the undisplaced polygon. The behind body's condensed stiffness
// K_cc (condensed_response.h) mapped onto the active nodes gives their reaction
//   f = -K (u - u*),   K = map^T K_cc map   (symmetric, positive semidefinite),
// equal to the step's conveyed reaction (interaction_step.h) for any u while the
// collisions hold: exact, because the forcible displacement and the condensed FEM body are
// linear. The server rebuilds it when the pairs or polygons change (as it rebuilds an IR
// when an active set changes). Plain data; evaluation is allocation-free and noexcept.
// Units: m, N, N/m.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/fem/compliance.h"
#include "common/interaction/forcible_displacement.h"

namespace cohaptic {

struct LinearBacking {
  std::vector<int> nodes;                ///< the front body's colliding nodes
  Eigen::MatrixXd stiffness;             ///< K, 3|nodes| x 3|nodes| [N/m]
  Eigen::VectorXd contact_displacement;  ///< u*, 3 per node [m]
};

/// The backing of `collisions` displacing `displacement.nodes` of a behind body whose
/// condensed stiffness on those nodes is `passive_stiffness` (3|displaced| square);
/// `active_rest_positions` per front-body node [m].
LinearBacking build_linear_backing(std::span<const PolygonCollision> collisions,
                                   const ForcibleDisplacement& displacement,
                                   const Eigen::MatrixXd& passive_stiffness,
                                   const Eigen::Ref<const Eigen::Matrix3Xd>& active_rest_positions);

/// f = -K (u - u*) for displacements u (3 per node of backing.nodes); f and u sized
/// 3|nodes|.
void evaluate_linear_backing(const LinearBacking& backing,
                             const Eigen::Ref<const Eigen::VectorXd>& displacement,
                             Eigen::Ref<Eigen::VectorXd> force) noexcept;

}  // namespace cohaptic
