// A root of a continuous function inside a bracket, by the Illinois variant of regula falsi:
// superlinear on the smooth, piecewise-linear functions the fracture and sliding solves
// meet, and never leaving the bracket. noexcept and allocation-free (for the haptic path).
#pragma once

#include <algorithm>
#include <cmath>

namespace cohaptic {

/// x in [a, b] with |f(x)| <= tolerance, given f(a) = fa and f(b) = fb of opposite signs
/// (or one of them zero); after 100 steps, the best point found.
template <typename Function>
double bracketed_root(const Function& f, double a, double b, double fa, double fb,
                      double tolerance) noexcept {
  if (std::abs(fa) <= tolerance) return a;
  if (std::abs(fb) <= tolerance) return b;
  for (int step = 0; step < 100; ++step) {
    double c = b - fb * (b - a) / (fb - fa);
    if (!(c >= std::min(a, b) && c <= std::max(a, b))) c = 0.5 * (a + b);
    const double fc = f(c);
    if (std::abs(fc) <= tolerance || std::abs(b - a) <= 1e-15 * std::max(std::abs(a), std::abs(b)))
      return c;
    if ((fc < 0) != (fb < 0)) {
      a = b;
      fa = fb;
    } else {
      fa *= 0.5;
    }
    b = c;
    fb = fc;
  }
  return b;
}

}  // namespace cohaptic
