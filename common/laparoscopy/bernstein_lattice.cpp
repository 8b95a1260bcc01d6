#include "common/laparoscopy/bernstein_lattice.h"

#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {

BernsteinLattice identity_lattice(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  if (!lo.allFinite() || !hi.allFinite())
    throw Error("FFD lattice: a corner of its box is not finite");
  for (int axis = 0; axis < 3; ++axis)
    if (!(hi[axis] > lo[axis]))
      throw Error(fmt::format("FFD lattice: the box is empty along axis {} (lo {} m, hi {} m)",
                              axis, lo[axis], hi[axis]));
  BernsteinLattice lattice{lo, hi, LatticeControl::Zero()};
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i)
        lattice.control.col(i + 4 * j + 16 * k) =
            lo + Eigen::Vector3d(i, j, k).cwiseProduct(hi - lo) / 3.0;
  return lattice;
}

Eigen::Vector4d cubic_bernstein(double t) noexcept {
  const double s = 1 - t;
  return {s * s * s, 3 * t * s * s, 3 * t * t * s, t * t * t};
}

Eigen::Vector3d lattice_coordinates(const BernsteinLattice& lattice,
                                    const Eigen::Vector3d& x) noexcept {
  return (x - lattice.lo).cwiseQuotient(lattice.hi - lattice.lo);
}

LatticeBasis lattice_basis(const BernsteinLattice& lattice, const Eigen::Vector3d& x) noexcept {
  const Eigen::Vector3d uvw = lattice_coordinates(lattice, x);
  const Eigen::Vector4d bu = cubic_bernstein(uvw[0]), bv = cubic_bernstein(uvw[1]),
                        bw = cubic_bernstein(uvw[2]);
  LatticeBasis basis;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) basis[i + 4 * j + 16 * k] = bu[i] * bv[j] * bw[k];
  return basis;
}

Eigen::Vector3d ffd_point(const BernsteinLattice& lattice, const Eigen::Vector3d& x) noexcept {
  return lattice.control * lattice_basis(lattice, x);
}

LatticeBinding bind_to_lattice(const BernsteinLattice& lattice, const Eigen::Matrix3Xd& rest) {
  LatticeBinding binding(12, rest.cols());
  for (Eigen::Index v = 0; v < rest.cols(); ++v) {
    const Eigen::Vector3d uvw = lattice_coordinates(lattice, rest.col(v));
    for (int axis = 0; axis < 3; ++axis)
      binding.block<4, 1>(4 * axis, v) = cubic_bernstein(uvw[axis]);
  }
  return binding;
}

void deform_ffd(const LatticeBinding& binding, const LatticeControl& control,
                Eigen::Matrix3Xd& deformed) noexcept {
  for (Eigen::Index v = 0; v < binding.cols(); ++v) {
    // Sum over k, then j, then i: 4 + 16 + 64 multiplications of 3-vectors by scalars.
    Eigen::Vector3d q = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) {
      Eigen::Vector3d plane = Eigen::Vector3d::Zero();
      for (int j = 0; j < 4; ++j) {
        const int row = 4 * j + 16 * k;
        const Eigen::Vector3d line =
            control.col(row) * binding(0, v) + control.col(row + 1) * binding(1, v) +
            control.col(row + 2) * binding(2, v) + control.col(row + 3) * binding(3, v);
        plane += binding(4 + j, v) * line;
      }
      q += binding(8 + k, v) * plane;
    }
    deformed.col(v) = q;
  }
}

}  // namespace cohaptic
