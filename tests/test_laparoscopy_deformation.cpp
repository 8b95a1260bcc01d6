// Display deformations of the laparoscopy model (common/laparoscopy/): the local
// polynomial of Eq. 1 against its profile values, and free-form deformation (Eqs. 2-3)
// with direct manipulation (Eqs. 6-7) against what must hold exactly: the identity
// lattice maps every point to itself, the Bernstein basis is a partition of unity, Eq. 7
// lands its point, and Eq. 6 equals the least-squares solution of an SVD (Eigen's
// JacobiSVD, the independent method); and the two ways a tissue's display is dented,
// compared on a sheet: both land P on A, the polynomial moves nothing beyond R, Eq. 7
// moves the whole tissue, and Eq. 6 pinning a rim about P makes the far tissue swing more.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <map>
#include <numbers>
#include <random>

#include "common/laparoscopy/direct_manipulation.h"
#include "common/laparoscopy/polynomial_deformation.h"
#include "common/laparoscopy/tissue_display.h"
#include "common/util/error.h"
#include "support/tissue_sheet.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;

TEST(PolynomialDeformation, ProfileValues) {
  const double radius = 0.02;
  EXPECT_EQ(polynomial_depth_fraction(0, radius), 1.0);
  EXPECT_EQ(polynomial_depth_fraction(radius / 2, radius), 0.75);
  EXPECT_EQ(polynomial_depth_fraction(radius, radius), 0.0);
  EXPECT_EQ(polynomial_depth_fraction(1.5 * radius, radius), 0.0);
  EXPECT_EQ(polynomial_depth_fraction(0.001, 0), 0.0);
}

TEST(PolynomialDeformation, MovesWithinTheRadiusAlongAP) {
  const double radius = 0.02;
  const PolynomialDent dent{Vector3d(0.01, 0.02, 0), Vector3d(0.012, 0.019, -0.006), radius};
  const Vector3d ap = dent.tool_point - dent.contact_point;
  Eigen::Matrix3Xd rest(3, 5);
  rest.col(0) = dent.contact_point;                                                   // r = 0
  rest.col(1) = dent.contact_point + Vector3d(radius / 2, 0, 0);                      // r = R/2
  rest.col(2) = dent.contact_point + Vector3d(0, radius, 0);                          // r = R
  rest.col(3) = dent.contact_point + Vector3d(0, 0.6 * radius, 0.8 * radius * 1.01);  // beyond R
  rest.col(4) = dent.contact_point + Vector3d(0.3 * radius, 0.4 * radius, 0);         // r = R/2 too
  Eigen::Matrix3Xd deformed(3, 5);
  deform_polynomial(rest, dent, deformed);
  EXPECT_LT((deformed.col(0) - dent.tool_point).norm(), 1e-17);  // P goes to A: depth a0 = |AP|
  EXPECT_LT((deformed.col(1) - rest.col(1) - 0.75 * ap).norm(), 1e-17);
  EXPECT_EQ(deformed.col(2), rest.col(2));
  EXPECT_EQ(deformed.col(3), rest.col(3));
  EXPECT_LT((deformed.col(4) - rest.col(4) - 0.75 * ap).norm(), 1e-17);
}

BernsteinLattice box_lattice() {
  return identity_lattice(Vector3d(-0.05, -0.04, -0.03), Vector3d(0.05, 0.06, 0.01));
}

std::vector<Vector3d> random_points_in(const BernsteinLattice& lattice, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<Vector3d> points;
  for (int i = 0; i < count; ++i)
    points.push_back(
        lattice.lo +
        Vector3d(unit(rng), unit(rng), unit(rng)).cwiseProduct(lattice.hi - lattice.lo));
  return points;
}

TEST(FreeFormDeformation, BasisIsAPartitionOfUnity) {
  const BernsteinLattice lattice = box_lattice();
  for (const Vector3d& x : random_points_in(lattice, 500, 1)) {
    const LatticeBasis basis = lattice_basis(lattice, x);
    EXPECT_NEAR(basis.sum(), 1.0, 1e-15);
    EXPECT_GE(basis.minCoeff(), 0.0);
  }
}

TEST(FreeFormDeformation, IdentityLatticeIsExact) {
  const BernsteinLattice lattice = box_lattice();
  const std::vector<Vector3d> points = random_points_in(lattice, 500, 2);
  Eigen::Matrix3Xd rest(3, static_cast<Eigen::Index>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) {
    rest.col(static_cast<Eigen::Index>(i)) = points[i];
    EXPECT_LT((ffd_point(lattice, points[i]) - points[i]).norm(), 1e-16);
  }
  Eigen::Matrix3Xd deformed(3, rest.cols());
  deform_ffd(bind_to_lattice(lattice, rest), lattice.control, deformed);
  EXPECT_LT((deformed - rest).cwiseAbs().maxCoeff(), 1e-16);
  EXPECT_THROW(identity_lattice(Vector3d::Zero(), Vector3d(1, 0, 1)), Error);
}

TEST(FreeFormDeformation, BindingEqualsTheTripleSum) {
  BernsteinLattice lattice = box_lattice();
  std::mt19937 rng(4);
  std::normal_distribution<double> jiggle(0, 0.01);
  for (int c = 0; c < kLatticeControlPoints; ++c)
    lattice.control.col(c) += Vector3d(jiggle(rng), jiggle(rng), jiggle(rng));
  const std::vector<Vector3d> points = random_points_in(lattice, 200, 5);
  Eigen::Matrix3Xd rest(3, static_cast<Eigen::Index>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i)
    rest.col(static_cast<Eigen::Index>(i)) = points[i];
  Eigen::Matrix3Xd deformed(3, rest.cols());
  deform_ffd(bind_to_lattice(lattice, rest), lattice.control, deformed);
  for (std::size_t i = 0; i < points.size(); ++i) {
    // Eq. 2 literally: the triple sum over P_ijk B_i(u) B_j(v) B_k(w).
    const Vector3d uvw = lattice_coordinates(lattice, points[i]);
    Vector3d q = Vector3d::Zero();
    for (int i3 = 0; i3 < 4; ++i3)
      for (int j3 = 0; j3 < 4; ++j3)
        for (int k3 = 0; k3 < 4; ++k3)
          q += lattice.control.col(i3 + 4 * j3 + 16 * k3) * cubic_bernstein(uvw[0])[i3] *
               cubic_bernstein(uvw[1])[j3] * cubic_bernstein(uvw[2])[k3];
    EXPECT_LT((deformed.col(static_cast<Eigen::Index>(i)) - q).norm(), 1e-16);
  }
}

TEST(DirectManipulation, Eq7LandsThePoint) {
  BernsteinLattice lattice = box_lattice();
  const Vector3d grasp(0.01, 0.005, -0.002), target_shift(0.002, -0.001, 0.008);
  lattice.control += single_point_manipulation(lattice_basis(lattice, grasp), target_shift);
  EXPECT_LT((ffd_point(lattice, grasp) - (grasp + target_shift)).norm(), 1e-17);
  // Elsewhere the space moves less, and far away hardly at all.
  const Vector3d elsewhere(-0.04, 0.05, -0.025);
  EXPECT_LT((ffd_point(lattice, elsewhere) - elsewhere).norm(), 0.2 * target_shift.norm());
}

using Bases = Eigen::Matrix<double, kLatticeControlPoints, Eigen::Dynamic>;

/// The SVD's least-squares (minimal-norm) solution of B dP^T = dQ^T.
LatticeControl svd_solution(const Bases& bases, const Eigen::Matrix3Xd& displacements) {
  const Eigen::MatrixXd b = bases.transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(b, Eigen::ComputeThinU | Eigen::ComputeThinV);
  return Eigen::MatrixXd(svd.solve(Eigen::MatrixXd(displacements.transpose()))).transpose();
}

TEST(DirectManipulation, Eq6EqualsTheSvdLeastSquaresSolution) {
  const BernsteinLattice lattice = box_lattice();
  std::mt19937 rng(9);
  std::normal_distribution<double> shift(0, 0.003);
  for (const int m : {1, 2, 5, 20, 40, 100, 300}) {
    const std::vector<Vector3d> points =
        random_points_in(lattice, m, static_cast<unsigned>(10 + m));
    Bases bases(kLatticeControlPoints, m);
    Eigen::Matrix3Xd displacements(3, m);
    for (int i = 0; i < m; ++i) {
      bases.col(i) = lattice_basis(lattice, points[static_cast<std::size_t>(i)]);
      displacements.col(i) = Vector3d(shift(rng), shift(rng), shift(rng));
    }
    const LatticeControl eq6 = least_squares_manipulation(bases, displacements);
    const LatticeControl svd = svd_solution(bases, displacements);
    EXPECT_LT((eq6 - svd).norm(), 1e-8 * svd.norm()) << m << " points";
    if (m <= 20) {  // fewer points than control points, well conditioned: every one lands
      const Eigen::Matrix3Xd landed = eq6 * bases;
      EXPECT_LT((landed - displacements).norm(), 1e-12 * displacements.norm()) << m << " points";
    }
  }
}

TEST(DirectManipulation, Eq6ReducesToEq7ForOnePoint) {
  const BernsteinLattice lattice = box_lattice();
  const LatticeBasis basis = lattice_basis(lattice, Vector3d(-0.01, 0.02, -0.01));
  const Vector3d shift(0.001, 0.002, -0.004);
  const LatticeControl eq7 = single_point_manipulation(basis, shift);
  const LatticeControl eq6 = least_squares_manipulation(Bases(basis), Eigen::Matrix3Xd(shift));
  EXPECT_LT((eq6 - eq7).norm(), 1e-14 * eq7.norm());
}

TEST(DirectManipulation, Eq7SuperposedMissesWhatEq6Holds) {
  // The grasp point pulled 8 mm while a point 15 mm away is pinned: Eq. 6 honours both;
  // Eq. 7 per point, summed, moves the pinned point and undershoots the grasp.
  const BernsteinLattice lattice = box_lattice();
  const Vector3d grasp(0, 0.01, -0.01), pinned(0.015, 0.01, -0.01);
  Bases bases(kLatticeControlPoints, 2);
  bases.col(0) = lattice_basis(lattice, grasp);
  bases.col(1) = lattice_basis(lattice, pinned);
  Eigen::Matrix3Xd wanted(3, 2);
  wanted.col(0) = Vector3d(0, 0, 0.008);
  wanted.col(1).setZero();
  const Eigen::Matrix3Xd eq6 = least_squares_manipulation(bases, wanted) * bases;
  const LatticeControl eq7_sum = single_point_manipulation(bases.col(0), wanted.col(0)) +
                                 single_point_manipulation(bases.col(1), wanted.col(1));
  const Eigen::Matrix3Xd eq7 = eq7_sum * bases;
  EXPECT_LT((eq6 - wanted).norm(), 1e-15);
  EXPECT_GT(eq7.col(1).norm(), 1e-3);  // the pinned point moved by more than a millimetre
}

TEST(DirectManipulation, DependentPointsAreRefused) {
  const BernsteinLattice lattice = box_lattice();
  Bases bases(kLatticeControlPoints, 2);
  bases.col(0) = bases.col(1) = lattice_basis(lattice, Vector3d(0.01, 0.01, 0));
  try {
    least_squares_manipulation(bases, Eigen::Matrix3Xd::Zero(3, 2));
    ADD_FAILURE() << "a point given twice was accepted";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("given twice"), std::string::npos) << e.what();
  }
  EXPECT_THROW(least_squares_manipulation(bases, Eigen::Matrix3Xd::Zero(3, 3)), Error);
}

/// Largest displacement of the sheet's vertices farther than `beyond` from `centre`.
double far_motion(const Eigen::Matrix3Xd& rest, const Eigen::Matrix3Xd& deformed,
                  const Vector3d& centre, double beyond) {
  double largest = 0;
  for (Eigen::Index v = 0; v < rest.cols(); ++v)
    if ((rest.col(v) - centre).norm() > beyond)
      largest = std::max(largest, (deformed.col(v) - rest.col(v)).norm());
  return largest;
}

TEST(TissueDisplay, BothMethodsLandPOnAThePolynomialLocallyEq7Globally) {
  const TriangleSurface sheet = testing::equilateral_sheet(30, 30, 0.002);  // 6 cm square
  const double radius = 0.01;
  Eigen::Index centre = 0;
  for (Eigen::Index v = 1; v < sheet.vertices.cols(); ++v)
    if (sheet.vertices.col(v).norm() < sheet.vertices.col(centre).norm()) centre = v;
  const Vector3d p = sheet.vertices.col(centre);
  const Vector3d a = p + Vector3d(0.001, -0.0005, 0.006);  // the forceps pull up and aside
  std::map<DisplayDeformation, double> far;
  for (const DisplayDeformation method :
       {DisplayDeformation::polynomial, DisplayDeformation::ffd_one_point}) {
    const TissueDisplay display = make_tissue_display(sheet.vertices, radius, method);
    Eigen::Matrix3Xd deformed(3, sheet.vertices.cols());
    display_tissue(display, p, a, deformed);
    EXPECT_LT((deformed.col(centre) - a).norm(), 1e-12) << static_cast<int>(method);
    far[method] = far_motion(sheet.vertices, deformed, p, 2 * radius);
    Eigen::Matrix3Xd at_rest(3, sheet.vertices.cols());
    display_tissue(display, p, Vector3d(std::nan(""), 0, 0), at_rest);
    EXPECT_EQ(at_rest, sheet.vertices);
  }
  EXPECT_EQ(far[DisplayDeformation::polynomial], 0.0);
  EXPECT_GT(far[DisplayDeformation::ffd_one_point],
            0.5 * (a - p).norm());  // Eq. 7 moves the whole tissue

  // Why the display offers no Eq. 6 with a pinned rim: holding eight points on a circle of
  // radius R about P (perpendicular to AP) still while P lands on A makes this coarse
  // lattice swing the far tissue more than Eq. 7 alone does.
  const TissueDisplay display =
      make_tissue_display(sheet.vertices, radius, DisplayDeformation::ffd_one_point);
  constexpr int kRim = 8;
  Eigen::Matrix<double, kLatticeControlPoints, Eigen::Dynamic> bases(kLatticeControlPoints,
                                                                     kRim + 1);
  Eigen::Matrix3Xd wanted = Eigen::Matrix3Xd::Zero(3, kRim + 1);
  bases.col(0) = lattice_basis(display.lattice, p);
  wanted.col(0) = a - p;
  const Vector3d axis = (a - p).normalized(), e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  for (int i = 0; i < kRim; ++i) {
    const double angle = 2 * std::numbers::pi * i / kRim;
    bases.col(i + 1) =
        lattice_basis(display.lattice, p + radius * (std::cos(angle) * e1 + std::sin(angle) * e2));
  }
  const LatticeControl pinned = display.lattice.control + least_squares_manipulation(bases, wanted);
  EXPECT_LT((pinned * bases - (display.lattice.control * bases + wanted)).norm(),
            1e-12);  // all nine land
  Eigen::Matrix3Xd deformed(3, sheet.vertices.cols());
  deform_ffd(display.binding, pinned, deformed);
  EXPECT_GT(far_motion(sheet.vertices, deformed, p, 2 * radius),
            2 * far[DisplayDeformation::ffd_one_point]);

  EXPECT_THROW(make_tissue_display(sheet.vertices, 0, DisplayDeformation::polynomial), Error);
  EXPECT_THROW(make_tissue_display(Eigen::Matrix3Xd(3, 0), radius, DisplayDeformation::polynomial),
               Error);
}

}  // namespace
}  // namespace cohaptic
