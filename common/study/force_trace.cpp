#include "common/study/force_trace.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "common/util/error.h"

namespace cohaptic {

void validate(const ForceTrace& trace) {
  const std::size_t n = trace.time_s.size();
  if (trace.force.size() != n || trace.position.size() != n)
    throw Error(
        fmt::format("force trace: {} times, {} forces and {} positions; they must be as many", n,
                    trace.force.size(), trace.position.size()));
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(trace.time_s[k]) || !trace.force[k].allFinite() ||
        !trace.position[k].allFinite())
      throw Error(fmt::format("force trace: sample {} is not finite", k));
    if (k > 0 && !(trace.time_s[k] > trace.time_s[k - 1]))
      throw Error(fmt::format(
          "force trace: time must strictly increase, but sample {} is at {} s after {} s", k,
          trace.time_s[k], trace.time_s[k - 1]));
  }
}

double peak_force_n(const ForceTrace& trace) {
  double peak = 0;
  for (const Eigen::Vector3d& f : trace.force) peak = std::max(peak, f.norm());
  return peak;
}

std::vector<Stroke> find_strokes(const ForceTrace& trace, double threshold_n) {
  validate(trace);
  if (!(threshold_n >= 0))
    throw Error(fmt::format("stroke threshold must be >= 0 N, got {}", threshold_n));
  std::vector<Stroke> strokes;
  const std::size_t n = trace.size();
  std::size_t k = 0;
  while (k < n) {
    if (trace.force[k].norm() <= threshold_n) {
      ++k;
      continue;
    }
    Stroke stroke{k, k};
    while (k < n && trace.force[k].norm() > threshold_n) ++k;
    stroke.end = k;
    if (!strokes.empty() &&
        trace.time_s[stroke.begin] - trace.time_s[strokes.back().end - 1] < kMinReleaseS)
      strokes.back().end = stroke.end;  // a dip within one press
    else
      strokes.push_back(stroke);
  }
  return strokes;
}

std::vector<Stroke> find_strokes(const ForceTrace& trace) {
  return find_strokes(trace, kDefaultContactFraction * peak_force_n(trace));
}

double duration_s(const ForceTrace& trace, const Stroke& stroke) {
  if (stroke.size() == 0) return 0;
  return trace.time_s[stroke.end - 1] - trace.time_s[stroke.begin];
}

}  // namespace cohaptic
