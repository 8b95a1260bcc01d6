// Fracture by an excessive normal force (the separation-forces paper, Sec. V.F.2).
//
// The paper's energy balance with du = 0 (the deformation around the crack edge moves
// with it but keeps its shape): while the tool pulls the pulled body away from the base
// by dz with the normal force at F_n = J_c l_n, the work F_n dz separates dLambda = l_n dz
// (Eqs. 12–14). In a tick that moves the deflection from delta_old to delta_new:
//   1. nothing happens unless the normal component of the field force at delta_new (with
//      the areas as they are) exceeds F_n, the tool moves away from the base, and a crack
//      front lies in the contact's region (cracks grow only from crack edges);
//   2. the part of the move that brings the normal force up to F_n is elastic; the rest,
//      dz_f along the normal, is fracture: Lambda grows by l_n dz_f;
//   3. that area goes to the front of the contact's region (which softens the contact's
//      own fields, F -> F-bar) and to the rest of the front (which only moves A(S-bar)),
//      split so that the normal force stays at F_n exactly. If even all of it in the
//      contact's region cannot bring the force down (the region is used up, or l_n is too
//      short for these fields), the force rises above F_n: `held` is false. If even none
//      of it there overshoots, less area separates (the rest of the move is elastic).
// So the work of the fracture part, F_n dz_f, equals J_c times the area it separates.
// noexcept, no allocation. Units: m, m^2, N.
#pragma once

#include <Eigen/Core>

#include "common/separation/separation_force.h"

namespace cohaptic {

struct NormalFracture {
  double separated = 0;        ///< area separated [m^2]
  double fracture_motion = 0;  ///< dz_f [m]
  bool held = true;            ///< the normal force ends at F_n
};

NormalFracture normal_fracture(const SeparationPatch& patch, SeparationState& state, const ContactPoint& contact,
                               const Eigen::Vector3d& contact_position, const Eigen::Vector3d& delta_old,
                               const Eigen::Vector3d& delta_new) noexcept;

/// The shortest l_n for which a pull along the normal at `node` of a fully connected
/// interface can hold F_n = J_c l_n with its growth inside D_n: with k and k-bar the
/// connected and locally separated fields' normal stiffness at zero deflection,
///   l_n >= k sqrt(|D_n| / ((k - k-bar) J_c))
/// (the rate l_n at which area may separate must at least match the rate that keeps the
/// force flat where fracture starts, which is where it is highest). Infinite if k <= k-bar.
double holding_normal_length(const SeparationPatch& patch, int node, int tool_node = 0);

}  // namespace cohaptic
