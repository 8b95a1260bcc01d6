// Percentiles of a sample.
#pragma once

#include <vector>

namespace cohaptic {

/// The p-quantile (0 <= p <= 1) of `values` by linear interpolation between order
/// statistics at rank p (m - 1); NaN if `values` is empty.
double percentile(std::vector<double> values, double p);

}  // namespace cohaptic
