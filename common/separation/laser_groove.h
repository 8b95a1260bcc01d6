// Laser vaporisation of the connection between the layers (the separation-forces paper,
// Sec. V.G), stepped at the haptic rate.
//
// Steady-state dissection: the groove follows the fibre as long as the fibre moves no
// faster than v_s = alpha P / (q l_f^2) (Eq. 20); then each tick's move of the tip from a
// to b vaporises, on the interface, the strip of width l_f along the segment (flat ends,
// so consecutive ticks tile it): the area l_f |b - a| (Eqs. 15–17). Faster than v_s the
// absorbed energy per length cannot vaporise the volume l_f^2 dx and nothing is removed.
// A held fibre does not extend the groove. Only triangles whose plane both ends of the
// segment are within `reach` of take part; each gains at most its connected area. Tissue
// is vaporised once: the part of a tick's strip that lies in the groove record
// (separation_state.h) adds nothing, so passes over a groove, or across one, separate
// only what no pass took before (a tick that vaporises something is remembered) (the share of the
// strip already taken is read at 64 points spread over it). Heat conduction is neglected, as in the
// paper. The groove's triangles are open: a crack edge a tool can then open (Sec. VI.C). noexcept,
// no allocation. Units: m, m^2, s, m/s.
#pragma once

#include <Eigen/Core>

#include "common/separation/separation_state.h"

namespace cohaptic {

struct LaserFibre {
  bool firing = false;                                 ///< the previous tick had the laser on
  Eigen::Vector3d last_tip = Eigen::Vector3d::Zero();  ///< [m]
};

struct LaserSample {
  double vaporised = 0;  ///< area separated this tick [m^2]
  double speed = 0;      ///< of the tip [m/s]
  bool vaporising = false;
};

/// One tick of length dt [s] with the fibre's tip at `tip` and the laser `on`.
LaserSample step_laser(const SeparationPatch& patch, SeparationState& state, LaserFibre& fibre,
                       const Eigen::Vector3d& tip, bool on, double dt) noexcept;

/// The share of the strip of `width` along a-b, in the plane whose normal is `normal`,
/// that no segment of `groove` covers: 1 on fresh tissue, 0 on a groove's repeat.
double uncovered_share(const GrooveRecord& groove, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b, double width,
                       const Eigen::Vector3d& normal) noexcept;

/// Adds the strip of `width` along a-b to the record: it lengthens the last segment when
/// the strip continues it (starts at its end, same width, within 2 % of the width of its
/// line, counting what earlier merges strayed), else it takes a segment of its own, or
/// sets `full` when there is none left.
void remember_groove(GrooveRecord& groove, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                     double width) noexcept;

/// The area of triangle t covered by the strip of `width` along segment a-b, both
/// projected on the triangle's plane [m^2].
double strip_area_in_triangle(const SeparationPatch& patch, int t, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b, double width) noexcept;

}  // namespace cohaptic
