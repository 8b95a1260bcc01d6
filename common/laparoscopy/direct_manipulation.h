// Direct manipulation of a free-form deformation (the laparoscopy paper's Eqs. 4-7, after
// Hsu et al.): the surgeon moves points of the tissue, not control points, so the control
// displacement dP is solved from the wanted point displacements dQ = B dP.
//   Eq. 6, several points: dP = B+ dQ with B the m x 64 matrix of their bases; for m <= 64
//     independent points this is B^T (B B^T)^-1 dQ, the smallest dP that lands every point
//     exactly (e.g. the grasp point moved while other points are pinned); for m > 64 the
//     normal equations (B^T B)^-1 B^T dQ, the closest fit.
//   Eq. 7, one point: dP = B^T dQ / sum_i b_i^2, which Eq. 6 reduces to for m = 1; applied
//     to several points at once (summing each one's dP) it no longer lands them exactly.
// Units: m.
#pragma once

#include <Eigen/Core>

#include "common/laparoscopy/bernstein_lattice.h"

namespace cohaptic {

/// Eq. 7 for one point of basis `basis` moved by `displacement`. noexcept, allocation-free.
LatticeControl single_point_manipulation(const LatticeBasis& basis,
                                         const Eigen::Vector3d& displacement) noexcept;

/// Eq. 6: bases column per point (64 x m), displacements column per point (3 x m).
/// Throws NumericalError when the points' bases are (nearly) dependent (e.g. a point given
/// twice), and Error when the sizes disagree or there is no point.
LatticeControl least_squares_manipulation(
    const Eigen::Matrix<double, kLatticeControlPoints, Eigen::Dynamic>& bases,
    const Eigen::Matrix3Xd& displacements);

}  // namespace cohaptic
