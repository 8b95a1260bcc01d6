// The studentized range distribution: Q = (largest - smallest of k independent N(mu, sigma^2))
// / S, where nu S^2 / sigma^2 is an independent chi-squared with nu degrees of freedom
// (nu = infinity: S = sigma). Its upper quantiles are the yardsticks of Scheffe's paired
// comparisons (paired_comparison_analysis.h) and Tukey's honest significant difference.
//
//   P(Q <= q; k, inf) = k * integral over z of phi(z) [Phi(z) - Phi(z - q)]^(k-1)
//   P(Q <= q; k, nu)  = integral over s > 0 of f_nu(s) P(Q <= q s; k, inf),
//                       f_nu the density of sqrt(chi^2_nu / nu)
//
// Both integrals by adaptive Gauss-Kronrod quadrature (Boost.Math), to about 1e-11 in
// probability; the quantile by TOMS 748 root bracketing on that CDF, to about 1e-10 relative.
// Valid for k >= 2 and nu >= 1 (not necessarily whole).
#pragma once

namespace cohaptic {

/// P(Q <= q) for `groups` = k >= 2 and `degrees_of_freedom` = nu >= 1 (infinity allowed);
/// 0 for q <= 0. Throws Error for k or nu out of range, or q not a number.
double studentized_range_cdf(double q, int groups, double degrees_of_freedom);

/// The q with P(Q <= q) = p, for 0 < p < 1 (the upper 1 - p point). Throws Error for
/// arguments out of range.
double studentized_range_quantile(double p, int groups, double degrees_of_freedom);

}  // namespace cohaptic
