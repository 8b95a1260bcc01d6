// Polynomials through the origin, f(s) = c_1 s + c_2 s^2 + ... + c_d s^d: the form of each
// axis of a precomputed force-deflection field (no force without deflection).
//
// The fit is a least-squares solve (column-pivoting QR) in the scaled variable s / max|s|,
// so that the Vandermonde columns are of order one whatever the units; the coefficients
// are returned in the caller's units (c_k in N/m^k for a force against a deflection in m).
// With as many distinct non-zero samples as coefficients the fit interpolates them.
#pragma once

#include <span>
#include <vector>

namespace cohaptic {

/// c_1..c_d. Throws Error if degree < 1, the spans differ in length, a value is not
/// finite, or fewer than `degree` distinct non-zero abscissae are given.
std::vector<double> fit_polynomial_through_origin(std::span<const double> s,
                                                  std::span<const double> f, int degree);

/// f(s) by Horner's rule; `c` holds c_1..c_degree.
double polynomial_value(const double* c, int degree, double s) noexcept;
/// The integral of f from 0 to s (the field's potential energy along its axis).
double polynomial_integral(const double* c, int degree, double s) noexcept;

/// `count` abscissae in [-half_range, half_range], clustered towards the ends like
/// Chebyshev points (cos((2i + 1) pi / (2 count))): none is zero for an even count, the
/// middle one is exactly zero for an odd count (and tells a fit through the origin nothing).
std::vector<double> chebyshev_abscissae(int count, double half_range);

}  // namespace cohaptic
