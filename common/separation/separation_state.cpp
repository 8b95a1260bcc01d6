#include "common/separation/separation_state.h"

#include <algorithm>
#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {

SeparationState make_separation_state(const SeparationPatch& patch) {
  SeparationState state;
  state.separated.assign(static_cast<std::size_t>(patch.triangle_count()), 0.0);
  state.groove.segments.resize(kGrooveSegmentCapacity);
  return state;
}

void separate_triangles(const SeparationPatch& patch, SeparationState& state,
                        std::span<const int> triangles) {
  for (int t : triangles) {
    if (t < 0 || t >= patch.triangle_count())
      throw Error(fmt::format("separation: triangle {} is not on the patch ({} triangles)", t,
                              patch.triangle_count()));
    separate_in_triangle(patch, state, t, patch.areas[t]);
  }
}

double separate_in_triangle(const SeparationPatch& patch, SeparationState& state, int t,
                            double area) noexcept {
  const double room = (1 - state.separated[t]) * patch.areas[t];
  const double added = std::clamp(area, 0.0, room);
  if (added >= room) {
    state.separated[t] = 1;
  } else {
    state.separated[t] += added / patch.areas[t];
  }
  state.separated_area += added;
  return added;
}

double local_separated_share(const SeparationPatch& patch, const SeparationState& state,
                             int node) noexcept {
  double separated = 0;
  for (int t : patch.regions.of(node)) separated += state.separated[t] * patch.areas[t];
  return std::min(separated / patch.region_areas[node], 1.0);
}

}  // namespace cohaptic
