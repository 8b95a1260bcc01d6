#include "common/separation/crack_growth.h"

#include <algorithm>
#include <limits>

namespace cohaptic {
namespace {

bool in_region_of(const SeparationPatch& patch, int node, int t) noexcept {
  const std::span<const int> region = patch.regions.of(node);
  return std::binary_search(region.begin(), region.end(), t);
}

}  // namespace

bool ContactRegion::contains(int t) const noexcept {
  return std::find(triangles.begin(), triangles.begin() + count, t) != triangles.begin() + count;
}

ContactRegion contact_region(const SeparationPatch& patch, const ContactPoint& contact) noexcept {
  ContactRegion region;
  for (int k = 0; k < 3; ++k) {
    if (contact.weights[k] == 0) continue;
    for (int t : patch.regions.of(patch.triangles[contact.triangle][k]))
      if (!region.contains(t)) region.triangles[region.count++] = t;
  }
  return region;
}

double LocalGrowth::total_room() const noexcept {
  double sum = 0;
  for (int i = 0; i < count; ++i) sum += room[i];
  return sum;
}

LocalGrowth local_growth_order(const SeparationPatch& patch, const SeparationState& state,
                               const ContactRegion& region,
                               const Eigen::Vector3d& origin) noexcept {
  // Work on a copy of the region's shares: filling one triangle may open its neighbours.
  std::array<double, ContactRegion::kCapacity> separated{};
  for (int i = 0; i < region.count; ++i) separated[i] = state.separated[region.triangles[i]];
  const auto share = [&](int t) {
    for (int i = 0; i < region.count; ++i)
      if (region.triangles[i] == t) return separated[i];
    return state.separated[t];
  };
  LocalGrowth order;
  for (;;) {
    int best = -1;
    double best_distance = std::numeric_limits<double>::infinity();
    for (int i = 0; i < region.count; ++i) {
      if (!crack_may_grow(patch, region.triangles[i], share)) continue;
      const double distance = (patch.centroids[region.triangles[i]] - origin).squaredNorm();
      // The first candidate is taken whatever its distance: an IR's far-off centroid gives
      // an infinite one, which no other distance beats.
      if (best < 0 || distance < best_distance ||
          (distance == best_distance && region.triangles[i] < region.triangles[best])) {
        best = i;
        best_distance = distance;
      }
    }
    if (best < 0) break;
    order.triangles[order.count] = region.triangles[best];
    order.room[order.count] = (1 - separated[best]) * patch.areas[region.triangles[best]];
    ++order.count;
    separated[best] = 1;
  }
  return order;
}

ContactAreas areas_after_growth(const SeparationPatch& patch, const SeparationState& state,
                                const ContactPoint& contact, const LocalGrowth& order, double local,
                                double far) noexcept {
  ContactAreas areas = contact_areas(patch, state, contact.triangle);
  const Triangle& nodes = patch.triangles[contact.triangle];
  double left = local;
  for (int i = 0; i < order.count && left > 0; ++i) {
    const double added = std::min(left, order.room[i]);
    left -= added;
    for (int k = 0; k < 3; ++k)
      if (in_region_of(patch, nodes[k], order.triangles[i]))
        areas.local_separated[k] =
            std::min(areas.local_separated[k] + added / patch.region_areas[nodes[k]], 1.0);
  }
  areas.global_separated =
      std::min((state.separated_area + local + far) / patch.interface_area, 1.0);
  return areas;
}

double apply_local_growth(const SeparationPatch& patch, SeparationState& state,
                          const LocalGrowth& order, double amount) noexcept {
  double done = 0;
  for (int i = 0; i < order.count && done < amount; ++i)
    done += separate_in_triangle(patch, state, order.triangles[i],
                                 std::min(amount - done, order.room[i]));
  return done;
}

double front_room(const SeparationPatch& patch, const SeparationState& state,
                  const ContactRegion* excluded) noexcept {
  double room = 0;
  for (int t = 0; t < patch.triangle_count(); ++t)
    if (can_grow(patch, state, t) && !(excluded && excluded->contains(t)))
      room += (1 - state.separated[t]) * patch.areas[t];
  return room;
}

double grow_nearest(const SeparationPatch& patch, SeparationState& state,
                    const Eigen::Vector3d& origin, double amount,
                    const ContactRegion* excluded) noexcept {
  double done = 0;
  // Each pass fills (or finishes the amount in) one triangle; bounded by the triangle count.
  for (int pass = 0; pass < patch.triangle_count() && done < amount; ++pass) {
    int best = -1;
    double best_distance = std::numeric_limits<double>::infinity();
    for (int t = 0; t < patch.triangle_count(); ++t) {
      if (!can_grow(patch, state, t) || (excluded && excluded->contains(t))) continue;
      const double distance = (patch.centroids[t] - origin).squaredNorm();
      if (distance < best_distance) {
        best = t;
        best_distance = distance;
      }
    }
    if (best < 0) break;
    done += separate_in_triangle(patch, state, best, amount - done);
  }
  return done;
}

}  // namespace cohaptic
