// Fracture by the tool (the separation-forces paper, Sec. V.F), one tick of it.
//
// The paper's energy balance (Eq. 10) with du = 0 — the deformation around the crack edge
// moves with it but keeps its shape: while the tool moves by dx, the work F . dx separates
// dLambda = l dx, so F . dx = J_c dLambda. The crack front a move opens is
//   l(v) = l_n max(0, v . n) + l_t |v - (v . n) n|      (v the unit direction of the move,
//                                                         n the interface normal)
// which gives the paper's two cases: a pull away from the base, F_n = J_c l_n (Eq. 14), and
// a push along the interface, F_t = J_c l_t (Eq. 11); a move between them opens both ways
// at once and tears at the force that satisfies the same balance. The force that drives
// the crack is F's working part, f(v) = max(0, F . n) max(0, v . n) + F_t . v_t (pressing
// towards the base opens nothing). In a tick that moves the deflection from delta_old to
// delta_new along v:
//   1. nothing happens unless f(v) at delta_new (with the areas as they are) exceeds
//      J_c l(v) and a crack front lies in the contact's region (cracks grow only from
//      crack edges);
//   2. the part of the move that brings f(v) up to J_c l(v) is elastic; over the rest, dx_f,
//      Lambda grows by l(v) dx_f;
//   3. that area goes to the front of the contact's region (which softens the contact's
//      own fields, F -> F-bar) and to the rest of the front (which only moves A(S-bar)),
//      split so that f(v) ends at J_c l(v) exactly. If even all of it in the contact's
//      region cannot bring the force down (the region is used up, or l is too short for
//      these fields), the force ends above: `held` is false. If even none of it there
//      softens too much, less area separates (the rest of the move is elastic).
// So over the fracture part of every tick, the tool's work is J_c times the area it
// separates, whatever the speed and the direction. What the paper neglects, the elastic
// energy the fields release as they soften at fixed deflection, is dissipated with the
// area: the contact stays passive. noexcept, no allocation. Units: m, m^2, N.
#pragma once

#include <Eigen/Core>
#include <string>

#include "common/separation/separation_force.h"

namespace cohaptic {

/// l(v): the crack front a move along unit direction `v` opens, at interface normal `n` [m].
double opening_length(const SeparationPatch& patch, const Eigen::Vector3d& n,
                      const Eigen::Vector3d& v) noexcept;

/// f(v): the part of force F [N] that works to open the crack on a move along `v`.
double opening_force(const Eigen::Vector3d& force, const Eigen::Vector3d& n,
                     const Eigen::Vector3d& v) noexcept;

struct FractureStep {
  double separated = 0;        ///< area separated [m^2]
  double fracture_motion = 0;  ///< dx_f [m]
  bool in_reach = false;       ///< f(v) exceeded J_c l(v) with a crack front in reach
  bool held = true;            ///< f(v) ends at J_c l(v) or below
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  ///< v
  double threshold = 0;                                 ///< J_c l(v) [N]
};

FractureStep fracture_step(const SeparationPatch& patch, SeparationState& state,
                           const ContactPoint& contact, const Eigen::Vector3d& contact_position,
                           const Eigen::Vector3d& delta_old,
                           const Eigen::Vector3d& delta_new) noexcept;

/// The shortest l_n for which a pull along the normal at `node` of a fully connected
/// interface can hold F_n = J_c l_n with its growth inside D_n: with k and k-bar the
/// connected and locally separated fields' normal stiffness at zero deflection,
///   l_n >= k sqrt(|D_n| / ((k - k-bar) J_c))
/// (the rate l_n at which area may separate must at least match the rate that keeps the
/// force flat where fracture starts, which is where it is highest). Infinite if k <= k-bar.
double holding_normal_length(const SeparationPatch& patch, int node, int tool_node = 0);

/// Where over the interface a pull can hold F_n = J_c l_n: holding_normal_length at every
/// node (the tool's own node), against the patch's l_n.
struct PlateauReach {
  int nodes = 0;       ///< interface nodes
  int held = 0;        ///< of which l_n reaches their holding length
  double longest = 0;  ///< the longest holding length [m] (infinite: a node no l_n holds)
  Eigen::Vector3d where = Eigen::Vector3d::Zero();  ///< its node, at rest [m]
};

PlateauReach plateau_reach(const SeparationPatch& patch);

/// Empty if l_n holds the plateau at every node; otherwise a sentence naming how many nodes
/// it does not hold at, the bound (the longest holding length) and where it is needed.
std::string plateau_warning(const PlateauReach& reach, double normal_length);

}  // namespace cohaptic
