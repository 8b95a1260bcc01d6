#include "common/separation/polynomial_fit.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <numbers>

#include "common/util/error.h"

namespace cohaptic {

std::vector<double> fit_polynomial_through_origin(std::span<const double> s,
                                                  std::span<const double> f, int degree) {
  if (degree < 1) throw Error(fmt::format("polynomial fit: degree must be >= 1, got {}", degree));
  if (s.size() != f.size())
    throw Error(fmt::format("polynomial fit: {} abscissae but {} values", s.size(), f.size()));
  double scale = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!std::isfinite(s[i]) || !std::isfinite(f[i]))
      throw Error(fmt::format("polynomial fit: sample {} is not finite ({}, {})", i, s[i], f[i]));
    scale = std::max(scale, std::abs(s[i]));
  }
  std::vector<double> distinct;  // non-zero at the scale of the samples
  for (double x : s)
    if (std::abs(x) > 1e-12 * scale &&
        std::none_of(distinct.begin(), distinct.end(),
                     [&](double d) { return std::abs(d - x) <= 1e-12 * scale; }))
      distinct.push_back(x);
  if (static_cast<int>(distinct.size()) < degree)
    throw Error(
        fmt::format("polynomial fit: degree {} needs at least {} distinct non-zero samples, got {}",
                    degree, degree, distinct.size()));
  const auto rows = static_cast<Eigen::Index>(s.size());
  Eigen::MatrixXd vandermonde(rows, degree);
  Eigen::VectorXd values(rows);
  for (Eigen::Index i = 0; i < rows; ++i) {
    const double t = s[static_cast<std::size_t>(i)] / scale;
    double power = t;
    for (int k = 0; k < degree; ++k, power *= t) vandermonde(i, k) = power;
    values[i] = f[static_cast<std::size_t>(i)];
  }
  const Eigen::VectorXd scaled = vandermonde.colPivHouseholderQr().solve(values);
  std::vector<double> c(static_cast<std::size_t>(degree));
  double unit = 1;
  for (int k = 0; k < degree; ++k) {
    unit *= scale;
    c[static_cast<std::size_t>(k)] = scaled[k] / unit;
  }
  return c;
}

double polynomial_value(const double* c, int degree, double s) noexcept {
  double value = 0;
  for (int k = degree - 1; k >= 0; --k) value = value * s + c[k];
  return value * s;
}

double polynomial_integral(const double* c, int degree, double s) noexcept {
  double value = 0;
  for (int k = degree - 1; k >= 0; --k) value = value * s + c[k] / (k + 2);
  return value * s * s;
}

std::vector<double> chebyshev_abscissae(int count, double half_range) {
  std::vector<double> s(static_cast<std::size_t>(std::max(count, 0)));
  for (int i = 0; i < count; ++i)
    s[static_cast<std::size_t>(i)] =
        half_range * std::cos((2 * i + 1) * std::numbers::pi / (2 * count));
  if (count % 2 == 1) s[static_cast<std::size_t>(count / 2)] = 0;  // exactly, not cos(pi / 2)
  return s;
}

}  // namespace cohaptic
