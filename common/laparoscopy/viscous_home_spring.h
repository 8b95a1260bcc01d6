// The laparoscopy paper's viscous element: a dashpot c beside every home spring, so a vertex
// the instrument lets go of returns home slowly, and one it moves resists the motion.
//
// The vertex is massless (a Kelvin-Voigt element with the 1-ring springs added): the load on
// it is grad E(u) + c du/dt (home_spring_force.h), and left alone it relaxes by
//   c du/dt = -grad E(u),
// which with k2 = 0 is u(t) = u(0) exp(-k1 t / c): the time constant is c / k1.
// The instrument only pushes (the forceps' grasp holds it both ways): it holds the vertex
// while the load it must apply points along its shaft, into the tissue. Drawn back faster
// than the vertex returns, it lets go; the vertex relaxes on its own and the tool feels
// nothing until it reaches the vertex again (its displacement along the shaft at least the
// vertex's). The tool's velocity is its displacement's change over the tick; the tick on
// which it takes hold, or on which forceps grasp or let go (u is measured anew), has no
// damping term (the vertex jumps to it, being massless).
// One vertex moves per evaluator: one the tool has not touched is at rest. It goes on to the
// next patch (a new IR around another vertex) by its surface index. With c = 0 the contact
// is the elastic one of home_spring_contact.h, bit for bit.
// noexcept and allocation-free. Units: m, s, N, N s/m.
#pragma once

#include <Eigen/Core>

#include "common/laparoscopy/home_spring_contact.h"

namespace cohaptic {

/// Below this displacement a relaxing vertex is at home [m].
inline constexpr double kVertexAtHome = 1e-7;

/// The vertex that moves: the one the tool holds, or the one it let go of, relaxing.
struct MovingVertex {
  int vertex = -1;          ///< patch vertex; -1: every vertex is at rest
  int surface_vertex = -1;  ///< the same vertex on the body's surface
  bool held = false;
  bool grasped = false;  ///< held by forceps: u runs from the tool at the grasp, not from P
  Eigen::Vector3d contact_point = Eigen::Vector3d::Zero();  ///< P where it was pushed from [m]
  Eigen::Vector3d displacement = Eigen::Vector3d::Zero();   ///< u [m]
};

/// One linearly implicit Euler step of c du/dt = -grad E(u) over `dt` for touchable vertex
/// `vertex` of `patch` (damping > 0): (c/dt + H) du = -grad E(u), H the Hessian of E with
/// each compressed 1-ring spring's transverse term dropped, so the system stays positive
/// definite and the step stable for any dt. Exact rate e^(-h) replaced by 1/(1 + h), h = k1
/// dt / c, when k2 = 0.
Eigen::Vector3d relax_home_spring_vertex(const HomeSpringPatch& patch, int vertex,
                                         const Eigen::Vector3d& displacement, double dt) noexcept;

/// One haptic tick of the viscous body over `dt` [s] (> 0; 0: no time passes, no damping
/// term): the tool at `tool`, `moving` the state the previous tick left (updated). The contact
/// is the elastic one's, its force -(grad E(u) + c du/dt) while the tool holds the vertex;
/// not touching (and zero force) while it does not.
HomeSpringContact evaluate_viscous_home_spring(const PreparedHomeSpringPatch& prepared,
                                               MovingVertex& moving, const Eigen::Vector3d& tool,
                                               double dt) noexcept;

/// `moving`, made on another patch of the same body, moved onto patch `to`: its vertex
/// renumbered by its surface index; at rest if `to` cannot touch it.
void carry_moving_vertex(const HomeSpringPatch& to, MovingVertex& moving) noexcept;

}  // namespace cohaptic
