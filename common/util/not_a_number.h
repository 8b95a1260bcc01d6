// kNaN: the "no value" of measures, summaries and distances (a quiet NaN: it propagates
// through arithmetic, compares false, and prints as "nan" in the tables).
#pragma once

#include <limits>

namespace cohaptic {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace cohaptic
