// SeparationState: the mutable part of a separating interface — how much of each
// interface triangle is separated — and the normalised areas of the separation-forces
// paper (Eq. 2–3) read from it.
//
// separated[m] in [0, 1] is the separated share of triangle C_m; separated_area is the
// total separated area Lambda [m^2] of the whole interface (it may include separation
// outside a patch that is only part of the interface). A(S-bar) = Lambda / |C| and
// A(R-bar_n) = sum over D_n of separated[m] |C_m| / |D_n|; A(S) and A(R_n) are their
// complements (Eq. 3). A triangle is open when any of it is separated. A crack may grow
// into a triangle that is not fully separated and is open, has an open rim edge, or has
// an edge neighbour that is fully separated: cracks grow only from crack edges.
//
// The groove record remembers where lasers have vaporised (laser_groove.h), so that a pass
// over an existing groove separates nothing twice: strips of the spot's width along
// segments, a stroke's consecutive near-collinear ticks merged into one segment. It holds
// at most its buffer's size (make_separation_state's is kGrooveSegmentCapacity; a state
// read from the wire has none, so a client's prediction within one IR remembers nothing);
// once full, further grooves are vaporised but not remembered, and `full` says so.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/separation/separation_patch.h"

namespace cohaptic {

/// A vaporised strip: width `width` along a-b, flat ends [m]. The ticks merged into it lie
/// within `slack` of the line a-b [m].
struct GrooveSegment {
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double width = 0;
  double slack = 0;
};

inline constexpr std::size_t kGrooveSegmentCapacity = 1024;

struct GrooveRecord {
  std::vector<GrooveSegment> segments;  ///< the buffer; the first `count` are the record
  std::size_t count = 0;
  bool full = false;  ///< a groove was vaporised that the buffer had no room for
};

struct SeparationState {
  std::vector<double> separated;  ///< per patch triangle, in [0, 1]
  double separated_area = 0;      ///< Lambda [m^2]
  GrooveRecord groove;
};

/// Everything connected.
SeparationState make_separation_state(const SeparationPatch& patch);

/// Fully separates `triangles` (an initial crack). Throws Error for an index out of range.
void separate_triangles(const SeparationPatch& patch, SeparationState& state,
                        std::span<const int> triangles);

/// Separates up to `area` [m^2] more of triangle t; returns the area actually added.
double separate_in_triangle(const SeparationPatch& patch, SeparationState& state, int t,
                            double area) noexcept;

/// A(R-bar_n): the separated share of the region around node n.
double local_separated_share(const SeparationPatch& patch, const SeparationState& state,
                             int node) noexcept;

/// A(S-bar): the separated share of the whole interface.
inline double global_separated_share(const SeparationPatch& patch,
                                     const SeparationState& state) noexcept {
  return state.separated_area / patch.interface_area;
}

inline bool is_open(const SeparationState& state, int t) noexcept {
  return state.separated[static_cast<std::size_t>(t)] > 0;
}

/// Whether a crack may grow into triangle t (see above) when share(m) is the separated
/// share of triangle m.
template <typename Share>
bool crack_may_grow(const SeparationPatch& patch, int t, const Share& share) noexcept {
  if (share(t) >= 1) return false;
  if (share(t) > 0 || patch.open_rim[static_cast<std::size_t>(t)] != 0) return true;
  for (int neighbour : patch.neighbours[static_cast<std::size_t>(t)])
    if (neighbour >= 0 && share(neighbour) >= 1) return true;
  return false;
}

inline bool can_grow(const SeparationPatch& patch, const SeparationState& state, int t) noexcept {
  return crack_may_grow(patch, t,
                        [&](int m) { return state.separated[static_cast<std::size_t>(m)]; });
}

}  // namespace cohaptic
