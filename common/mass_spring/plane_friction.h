// Contact of a node with the supporting plane (the thin-objects paper, Sec. 4.4.1): the
// plane's normal and friction forces, and the inelastic velocity projection of Eq. (6).
//
// A node acts on the plane when it touches it (height <= kPlaneTouchTolerance) and its
// force F presses into it (F . N_p <= 0). Then, with F_n = |F . N_p| and F_t, v_t the
// tangential parts of the force and the velocity:
//   normal force  -(F . N_p) N_p  (cancels the pressing part);
//   sticking: the tangential force that stops the node within this step of length h,
//     f_stop = -(F_t + m v_t / h), if |f_stop| <= mu_d F_n for a sliding node (kinetic
//     friction can stop it) or <= mu_s F_n for a node at rest (v_t = 0: f_stop = -F_t, static
//     friction cancels the pull); the node's tangential velocity is then exactly 0;
//   sliding (v_t != 0, not stopped): dynamic friction -mu_d F_n v_t/|v_t|;
//   at rest and pulled harder than mu_s F_n: -mu_s F_n F_t/|F_t|.
// Stopping a sliding node with up to mu_s F_n would be friction above Coulomb's while it
// slides; on a barely damped network dragged at constant speed (the paper's alpha) it made the
// bottom nodes stick and slip, and their friction cancelled on average.
// Without the stopping test a node, once moving, could only come to rest by reversing
// within a step (settle_on_plane), and a load fluctuating above the static threshold for
// one step would leave it sliding under the weaker dynamic law for good. Units: SI.
#pragma once

#include <Eigen/Core>

#include "common/mass_spring/mass_spring_network.h"

namespace cohaptic {

/// A node this close above the plane touches it [m].
inline constexpr double kPlaneTouchTolerance = 1e-9;

/// Height of `x` above the plane [m] (negative below).
inline double height_above(const SupportPlane& plane, const Eigen::Vector3d& x) {
  return (x - plane.point).dot(plane.normal);
}

/// The plane's normal and friction force on a node of mass `mass` at `x` with velocity `v`
/// carrying the force `force`, for a step of h [s]; zero when it does not touch or does not
/// press. Sets `sliding` when the dynamic law applied.
Eigen::Vector3d plane_reaction(const SupportPlane& plane, const Eigen::Vector3d& x,
                               const Eigen::Vector3d& v, const Eigen::Vector3d& force, double mass,
                               double h, bool& sliding) noexcept;

/// After the velocity update of a touching node: removes a velocity into the plane
/// (Eq. 6) and, if dynamic friction reversed the sliding direction `v_before` within the
/// step, the tangential velocity.
void settle_on_plane(const SupportPlane& plane, const Eigen::Vector3d& v_before, bool sliding,
                     Eigen::Ref<Eigen::Vector3d> v) noexcept;

/// Moves a node below the plane back onto it and removes its velocity into the plane.
void keep_above(const SupportPlane& plane, Eigen::Ref<Eigen::Vector3d> x,
                Eigen::Ref<Eigen::Vector3d> v) noexcept;

}  // namespace cohaptic
