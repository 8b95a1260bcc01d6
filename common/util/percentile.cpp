#include "common/util/percentile.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cohaptic {

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const double rank = p * static_cast<double>(values.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(rank));
  const std::size_t hi = std::min(lo + 1, values.size() - 1);
  const double w = rank - static_cast<double>(lo);
  return values[lo] + w * (values[hi] - values[lo]);
}

}  // namespace cohaptic
