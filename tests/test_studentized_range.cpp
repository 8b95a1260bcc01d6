// The studentized range distribution (studentized_range.h) against independent answers: the
// range of two normals in closed form (2 Phi(q / sqrt 2) - 1) and, with a finite nu, as a
// Student t (Boost.Math's t distribution); R's ptukey at five points; the published table
// of upper points (Harter 1960 as extended by Gleason 1998); and its quantile inverting its CDF.
#include <gtest/gtest.h>

#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <limits>
#include <numbers>

#include "common/study/studentized_range.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

TEST(StudentizedRange, TheRangeOfTwoIsTheAbsoluteDifferenceOfTwoNormals) {
  for (double q : {0.1, 1.0, 2.772, 5.0}) {
    const double expected = std::erf(q / 2);  // 2 Phi(q / sqrt 2) - 1
    EXPECT_NEAR(studentized_range_cdf(q, 2, kInfinity), expected, 1e-11) << "q = " << q;
  }
  // With nu degrees of freedom, Q = sqrt 2 |T_nu|.
  for (double nu : {1.0, 2.0, 10.0, 1000.0}) {
    const boost::math::students_t t(nu);
    for (double q : {0.5, 2.0, 9.0}) {
      const double expected = 2 * boost::math::cdf(t, q / std::numbers::sqrt2) - 1;
      EXPECT_NEAR(studentized_range_cdf(q, 2, nu), expected, 1e-10)
          << "q = " << q << ", nu = " << nu;
    }
    EXPECT_NEAR(studentized_range_quantile(0.95, 2, nu),
                std::numbers::sqrt2 * boost::math::quantile(t, 0.975), 1e-8)
        << "nu = " << nu;
  }
}

// R's ptukey (Copenhaver and Holland's algorithm), as scipy's tests quote it.
TEST(StudentizedRange, TheCdfEqualsRsPtukey) {
  struct Point {
    double q;
    int k;
    double nu, p;
  };
  for (const Point& point :
       {Point{0.1, 3, 9001, 0.002752818526842}, Point{1, 10, 1000, 0.000526142388912},
        Point{1, 3, kInfinity, 0.240712641229283}, Point{4, 3, kInfinity, 0.987012338626815},
        Point{1, 10, kInfinity, 0.000519869467083}})
    EXPECT_NEAR(studentized_range_cdf(point.q, point.k, point.nu), point.p, 1e-7 * point.p)
        << "q " << point.q << " k " << point.k << " nu " << point.nu;
}

// Upper 5 % and 1 % points for k = 2..8 groups, as published to 4 significant digits.
TEST(StudentizedRange, TheQuantilesMatchThePublishedTable) {
  const double nus[] = {5, 8, 10, 20, 30, 60, 120, kInfinity};
  const double q05[8][7] = {{3.635, 4.602, 5.218, 5.673, 6.033, 6.330, 6.582},
                            {3.261, 4.041, 4.529, 4.886, 5.167, 5.399, 5.596},
                            {3.151, 3.877, 4.327, 4.654, 4.912, 5.124, 5.304},
                            {2.950, 3.578, 3.958, 4.232, 4.445, 4.620, 4.768},
                            {2.888, 3.486, 3.845, 4.102, 4.301, 4.464, 4.601},
                            {2.829, 3.399, 3.737, 3.977, 4.163, 4.314, 4.441},
                            {2.800, 3.356, 3.685, 3.917, 4.096, 4.241, 4.363},
                            {2.772, 3.314, 3.633, 3.858, 4.030, 4.170, 4.286}};
  const double q01[8][7] = {{5.702, 6.976, 7.804, 8.421, 8.913, 9.321, 9.669},
                            {4.745, 5.635, 6.204, 6.625, 6.959, 7.237, 7.474},
                            {4.482, 5.270, 5.769, 6.136, 6.428, 6.669, 6.875},
                            {4.024, 4.639, 5.018, 5.293, 5.510, 5.688, 5.839},
                            {3.889, 4.455, 4.799, 5.048, 5.242, 5.401, 5.536},
                            {3.762, 4.282, 4.594, 4.818, 4.991, 5.133, 5.253},
                            {3.702, 4.200, 4.497, 4.708, 4.872, 5.005, 5.118},
                            {3.643, 4.120, 4.403, 4.603, 4.757, 4.882, 4.987}};
  // A table entry is rounded to 3 decimals (and a few differ from exact in the last): the
  // point lies within 1.5e-3 of it when the CDF brackets p there (the CDF rises with q).
  const auto brackets = [](double p, int k, double nu, double table) {
    return studentized_range_cdf(table - 1.5e-3, k, nu) < p &&
           p < studentized_range_cdf(table + 1.5e-3, k, nu);
  };
  for (int row = 0; row < 8; ++row)
    for (int k = 2; k <= 8; ++k) {
      EXPECT_TRUE(brackets(0.95, k, nus[row], q05[row][k - 2])) << "k " << k << " nu " << nus[row];
      EXPECT_TRUE(brackets(0.99, k, nus[row], q01[row][k - 2])) << "k " << k << " nu " << nus[row];
    }
  // And the quantile itself, at the worked example's point (paired_comparison_analysis).
  EXPECT_NEAR(studentized_range_quantile(0.95, 3, 5), 4.602, 1.5e-3);
}

TEST(StudentizedRange, TheQuantileInvertsTheCdf) {
  // Small and large p, few and many groups, one degree of freedom (the heaviest tail), a
  // fractional one, and none missing.
  struct Case {
    double p;
    int k;
    double nu;
  };
  for (const auto& [p, k, nu] : {Case{0.01, 3, 30}, Case{0.5, 7, 4.434}, Case{0.95, 20, kInfinity},
                                 Case{0.999, 7, 1}, Case{0.999, 20, 1}, Case{0.99, 3, 2}}) {
    const double q = studentized_range_quantile(p, k, nu);
    EXPECT_NEAR(studentized_range_cdf(q, k, nu), p, 1e-9)
        << "p " << p << " k " << k << " nu " << nu;
  }
}

TEST(StudentizedRange, ArgumentsOutsideTheirRangesAreRefused) {
  EXPECT_THROW(studentized_range_cdf(1, 1, 10), Error);
  EXPECT_THROW(studentized_range_cdf(1, 3, 0.5), Error);
  EXPECT_THROW(studentized_range_cdf(std::nan(""), 3, 10), Error);
  EXPECT_THROW(studentized_range_quantile(1, 3, 10), Error);
  EXPECT_THROW(studentized_range_quantile(0, 3, 10), Error);
  EXPECT_EQ(studentized_range_cdf(-1, 3, 10), 0);
}

}  // namespace
}  // namespace cohaptic
