// Free-form deformation (the laparoscopy paper's Eqs. 2-3, after Sederberg and Parry): a
// 4 x 4 x 4 lattice of control points P_ijk spanning a box; a point whose box coordinates
// are (u, v, w) = (x - lo) / (hi - lo) componentwise maps to
//   Q(u, v, w) = sum_ijk P_ijk B_i(u) B_j(v) B_k(w)       (Q = B P, B a 1 x 64 row),
// with B_i the cubic Bernstein polynomials. The identity lattice (P_ijk = lo + (i, j, k)/3
// (hi - lo)) maps every point to itself, because cubic Bernstein polynomials reproduce
// linear functions; moving control points moves the space, and with it the surface.
// Control point (i, j, k) is column i + 4 j + 16 k. The lattice should enclose the
// vertices it deforms (outside it the polynomials extrapolate). A binding stores each
// vertex's 3 x 4 one-dimensional basis values once, so that a display frame costs the
// tensor-product sum alone. Units: m.
#pragma once

#include <Eigen/Core>

namespace cohaptic {

inline constexpr int kLatticeControlPoints = 64;
using LatticeBasis = Eigen::Matrix<double, kLatticeControlPoints, 1>;  ///< B of Eq. 3, as a column
using LatticeControl =
    Eigen::Matrix<double, 3, kLatticeControlPoints>;  ///< P (or dP), a column per point

struct BernsteinLattice {
  Eigen::Vector3d lo = Eigen::Vector3d::Zero();  ///< box corner at (u, v, w) = 0 [m]
  Eigen::Vector3d hi = Eigen::Vector3d::Ones();  ///< box corner at (u, v, w) = 1 [m]
  LatticeControl control = LatticeControl::Zero();
};

/// The lattice that leaves space unchanged over [lo, hi]; throws Error when a corner is not
/// finite or the box is empty along an axis.
BernsteinLattice identity_lattice(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

/// The four cubic Bernstein polynomials at t: (1-t)^3, 3t(1-t)^2, 3t^2(1-t), t^3.
Eigen::Vector4d cubic_bernstein(double t) noexcept;

/// (u, v, w) of x in the lattice's box.
Eigen::Vector3d lattice_coordinates(const BernsteinLattice& lattice,
                                    const Eigen::Vector3d& x) noexcept;

/// B of Eq. 3 at x: the 64 products B_i(u) B_j(v) B_k(w).
LatticeBasis lattice_basis(const BernsteinLattice& lattice, const Eigen::Vector3d& x) noexcept;

/// Q = B P: where the lattice moves the point x.
Eigen::Vector3d ffd_point(const BernsteinLattice& lattice, const Eigen::Vector3d& x) noexcept;

/// Per vertex, its one-dimensional basis values: rows 0-3 B_i(u), 4-7 B_j(v), 8-11 B_k(w).
using LatticeBinding = Eigen::Matrix<double, 12, Eigen::Dynamic>;

LatticeBinding bind_to_lattice(const BernsteinLattice& lattice, const Eigen::Matrix3Xd& rest);

/// deformed.col(v) = Q of vertex v under `control` (deformed sized like the binding by the
/// caller). noexcept, allocation-free.
void deform_ffd(const LatticeBinding& binding, const LatticeControl& control,
                Eigen::Matrix3Xd& deformed) noexcept;

}  // namespace cohaptic
