#include "common/study/studentized_range.h"

#include <fmt/format.h>

#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/tools/roots.hpp>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "common/util/error.h"

namespace cohaptic {

namespace {

// The inner integral (the range's CDF) is smooth and converges to round-off; the outer one,
// whose integrand carries the inner one's round-off, asks for less.
constexpr double kInnerTolerance = 1e-13, kOuterTolerance = 1e-11;  // relative
constexpr unsigned kInnerDepth = 10, kOuterDepth = 10;              // interval halvings at most
// Where the range's CDF P(range <= w) climbs from 0 to 1 for any k up to hundreds (it is 1 to
// round-off from about w = 18 on): the outer integral is split where q s crosses these w, so
// that a large q's narrow climb near s = 0 is not stepped over.
constexpr double kRangeClimb[] = {0.25, 0.5, 1, 2, 3, 4, 5, 6, 8, 10, 12, 15, 20};
constexpr double kNormalReach = 9;  // |z| beyond which phi(z) < 1e-17
// Beyond this many degrees of freedom S/sigma is within 1e-4 of 1 with odds of a few in 1e9,
// and the range's own distribution is used.
constexpr double kLargeDegreesOfFreedom = 1e7;

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::numbers::sqrt2); }
double normal_density(double x) { return std::exp(-0.5 * x * x) / std::sqrt(2 * std::numbers::pi); }

template <typename F>
double integrate(F&& f, double from, double to, double tolerance, unsigned depth) {
  return boost::math::quadrature::gauss_kronrod<double, 31>::integrate(f, from, to, depth,
                                                                       tolerance);
}

// P(range of k standard normals <= w).
double range_cdf(double w, int groups) {
  if (w <= 0) return 0;
  // P(range > w) <= 2k P(Z > w/2): beyond round-off of 1 here.
  if (2.0 * groups * normal_cdf(-0.5 * w) < 1e-17) return 1;
  const double value =
      groups * integrate(
                   [&](double z) {
                     // Phi(z) - Phi(z - w), from the nearer tails: no cancellation
                     // between two numbers near 1.
                     const double inside = z > 0.5 * w ? normal_cdf(w - z) - normal_cdf(-z)
                                                       : normal_cdf(z) - normal_cdf(z - w);
                     return inside <= 0 ? 0.0 : normal_density(z) * std::pow(inside, groups - 1);
                   },
                   -kNormalReach, kNormalReach, kInnerTolerance, kInnerDepth);
  return std::min(1.0, std::max(0.0, value));
}

// log of the density of s = sqrt(chi^2_nu / nu) at s > 0.
double log_scale_density(double s, double nu) {
  return std::log(2.0) + 0.5 * nu * std::log(0.5 * nu) - std::lgamma(0.5 * nu) +
         (nu - 1) * std::log(s) - 0.5 * nu * s * s;
}

void check_shape(int groups, double nu, const char* what) {
  if (groups < 2)
    throw Error(fmt::format("{}: {} groups; the studentized range needs at least 2", what, groups));
  if (!(nu >= 1))
    throw Error(fmt::format("{}: {} degrees of freedom; at least 1 is needed", what, nu));
}

}  // namespace

double studentized_range_cdf(double q, int groups, double nu) {
  check_shape(groups, nu, "studentized range");
  if (std::isnan(q)) throw Error("studentized range: q is not a number");
  if (q <= 0) return 0;
  if (nu > kLargeDegreesOfFreedom) return range_cdf(q, groups);
  // s's density is negligible (below e^-50 of its peak) outside [low, high].
  const double spread = 10 / std::sqrt(nu);
  const double low = std::max(0.0, 1 - spread), high = 1 + spread;
  std::vector<double> breaks{low, high};
  if (nu > 1) breaks.push_back(std::sqrt((nu - 1) / nu));  // the density's peak
  for (double w : kRangeClimb) breaks.push_back(w / q);
  std::sort(breaks.begin(), breaks.end());
  const auto integrand = [&](double s) {
    return s <= 0 ? 0.0 : std::exp(log_scale_density(s, nu)) * range_cdf(q * s, groups);
  };
  // Each piece to the same absolute accuracy, not relative to its own share (a piece near
  // s = 0 can be 1e-60 of the whole): its size, roughly, from its ends and middle.
  std::vector<std::pair<double, double>> pieces;
  std::vector<double> rough;
  double whole = 0;
  for (std::size_t b = 0; b + 1 < breaks.size(); ++b) {
    const double from = std::max(low, breaks[b]), to = std::min(high, breaks[b + 1]);
    if (to <= from) continue;
    pieces.emplace_back(from, to);
    rough.push_back((to - from) *
                    std::max({integrand(from), integrand(0.5 * (from + to)), integrand(to)}));
    whole += rough.back();
  }
  double value = 0;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const double tolerance =
        rough[i] > 0 ? std::min(0.1, std::max(kOuterTolerance, kOuterTolerance * whole / rough[i]))
                     : 0.1;
    value += integrate(integrand, pieces[i].first, pieces[i].second, tolerance, kOuterDepth);
  }
  return std::min(1.0, std::max(0.0, value));
}

double studentized_range_quantile(double p, int groups, double nu) {
  check_shape(groups, nu, "studentized range quantile");
  if (!(p > 0 && p < 1))
    throw Error(fmt::format("studentized range quantile: probability {} is not within (0, 1)", p));
  const auto below_p = [&](double q) { return studentized_range_cdf(q, groups, nu) - p; };
  // A bracket: the CDF rises from 0 at q = 0; double q until it passes p.
  double high = 4;
  while (below_p(high) < 0) {
    high *= 2;
    if (high > 1e9)
      throw Error(fmt::format("studentized range quantile: no q below 1e9 reaches p = {}", p));
  }
  std::uintmax_t iterations = 200;
  const auto [a, b] =
      boost::math::tools::toms748_solve(below_p, 0.0, high, -p, below_p(high),
                                        boost::math::tools::eps_tolerance<double>(34), iterations);
  return 0.5 * (a + b);
}

}  // namespace cohaptic
