// What the eye sees of a laparoscopy tissue: its surface vertices moved by one
// instrument's dent (P the collision point on the rest surface, A where the instrument
// holds it: the probe's tip, updated every frame; the grasp point and the forceps' pull,
// P fixed until release), by one of the paper's display deformations, chosen per scene:
//   polynomial      Eq. 1: vertices within R of P move along AP by (1 - r^2/R^2) |AP|;
//   ffd_one_point   a 4 x 4 x 4 Bernstein lattice around the whole surface whose control
//                   points move by Eq. 7 so that P lands on A: the paper's global
//                   deformation, in which the whole tissue follows, less with distance.
// A lattice this coarse cannot hold a dent local: pinning a rim around P by Eq. 6 makes the
// far tissue swing more than Eq. 7 alone (the deformation test shows it), so Eq. 6 is
// left to several wanted points (direct_manipulation.h), not offered here.
// Force is computed apart (home_spring_force.h): the paper decouples the two. noexcept
// and allocation-free per frame once made. Units: m.
#pragma once

#include <Eigen/Core>

#include "common/laparoscopy/bernstein_lattice.h"

namespace cohaptic {

enum class DisplayDeformation { polynomial, ffd_one_point };

struct TissueDisplay {
  Eigen::Matrix3Xd rest;  ///< surface vertices at rest [m]
  double radius = 0;      ///< radius of influence R [m]
  DisplayDeformation method = DisplayDeformation::polynomial;
  BernsteinLattice lattice;  ///< the rest vertices' bounding box grown by R on every side
  LatticeBinding binding;    ///< the rest vertices' basis values in it
};

/// Throws Error when there is no vertex, a vertex is not finite, or R is not positive and
/// finite.
TissueDisplay make_tissue_display(Eigen::Matrix3Xd rest, double radius, DisplayDeformation method);

/// deformed (sized like display.rest by the caller) = the rest surface dented by P -> A.
/// A point that is not finite leaves the surface at rest.
void display_tissue(const TissueDisplay& display, const Eigen::Vector3d& contact_point,
                    const Eigen::Vector3d& tool_point, Eigen::Matrix3Xd& deformed) noexcept;

}  // namespace cohaptic
