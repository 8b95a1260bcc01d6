// The one rule by which the server (find_contact) and the client (the IR's evaluator) pick
// the triangle nearest a tool. They must agree exactly, or the client would press another
// triangle than the one the server built the IR around.
//
// Nearest means smallest squared distance to the closed triangle. Triangles sharing the
// nearest edge or vertex are at the same distance up to rounding; among those the tool is
// assigned to the one whose plane it is deepest below (smallest signed height along the
// triangle's outward normal), then to the lower surface triangle index. "Same" is judged
// with the tolerances below. Units: squared distances in m^2, heights in m.
#pragma once

#include <cmath>
#include <limits>

namespace cohaptic {

/// Two squared distances closer than this (absolute part) are the same: 1e-24 m^2 is
/// (1 pm)^2, far below any mesh's size and above the rounding of a point on an edge.
inline constexpr double kNearestTieAbsolute2 = 1e-24;
/// ... or than this fraction of the best squared distance (relative part).
inline constexpr double kNearestTieRelative2 = 1e-12;
/// Two heights within this fraction of each other are the same.
inline constexpr double kNearestHeightRelative = 1e-15;

/// True when squared distance `d2` is nearer than `best_d2` by more than the tie tolerance.
inline bool strictly_nearer(double d2, double best_d2) noexcept {
  return d2 < best_d2 - (kNearestTieAbsolute2 + kNearestTieRelative2 * best_d2);
}

/// Runs the rule over candidates offered one by one; allocation-free, for the haptic path.
class NearestTriangleRule {
 public:
  /// Offers the triangle with surface index `surface_index` at squared distance `d2` whose
  /// plane the point is `height` above. Returns true if it becomes the nearest so far.
  bool offer(double d2, double height, int surface_index) noexcept {
    const double tie = kNearestTieAbsolute2 + kNearestTieRelative2 * distance2_;
    const bool same_distance = std::abs(d2 - distance2_) <= tie;
    const bool deeper = height < height_ - kNearestHeightRelative * std::abs(height_);
    const bool same_height =
        !deeper && height <= height_ + kNearestHeightRelative * std::abs(height_);
    const bool taken =
        surface_index_ < 0 || strictly_nearer(d2, distance2_) ||
        (same_distance && (deeper || (same_height && surface_index < surface_index_)));
    if (taken) {
      distance2_ = std::min(d2, distance2_);
      height_ = height;
      surface_index_ = surface_index;
    }
    return taken;
  }

  /// Squared distance of the nearest so far (the smallest offered); +inf before any offer.
  double distance2() const noexcept { return distance2_; }
  /// Height above the plane of the chosen triangle [m].
  double height() const noexcept { return height_; }
  /// Surface index of the chosen triangle; -1 before any offer.
  int surface_index() const noexcept { return surface_index_; }

 private:
  double distance2_ = std::numeric_limits<double>::infinity();
  double height_ = std::numeric_limits<double>::infinity();
  int surface_index_ = -1;
};

}  // namespace cohaptic
