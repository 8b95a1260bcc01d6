// Where new separated area goes when a crack grows: into the triangles at the crack front,
// nearest a given point first, and split between the contact's own region (the triangles
// around the nodes that carry the contact's weight, whose shares A(R-bar) change the
// contact force) and the rest of the front (which only changes A(S-bar)).
//
// A triangle is at the front when a crack may grow into it (can_grow). Filling one can
// bring its neighbours to the front, so the order in which the contact region fills is
// worked out in advance (local_growth_order); the force for any amount of local growth is
// then known without touching the state, which the fracture solve needs. Fixed-size
// storage only: noexcept, no allocation. Units: m, m^2.
#pragma once

#include <Eigen/Core>
#include <array>

#include "common/separation/separation_force.h"

namespace cohaptic {

/// The triangles of the regions D_k of the contact triangle's nodes with a non-zero weight.
struct ContactRegion {
  static constexpr int kCapacity = 3 * SeparationPatch::kMaxRegionTriangles;
  std::array<int, kCapacity> triangles{};
  int count = 0;
  bool contains(int t) const noexcept;
};

ContactRegion contact_region(const SeparationPatch& patch, const ContactPoint& contact) noexcept;

/// The contact region's triangles in the order a growing crack fills them (nearest
/// `origin` among those at the front, each filled before the next), with their room.
struct LocalGrowth {
  std::array<int, ContactRegion::kCapacity> triangles{};
  std::array<double, ContactRegion::kCapacity> room{};  ///< [m^2]
  int count = 0;
  double total_room() const noexcept;
};

LocalGrowth local_growth_order(const SeparationPatch& patch, const SeparationState& state,
                               const ContactRegion& region, const Eigen::Vector3d& origin) noexcept;

/// The contact's separated shares after `local` [m^2] of local growth and `far` of growth
/// elsewhere, without changing the state.
ContactAreas areas_after_growth(const SeparationPatch& patch, const SeparationState& state,
                                const ContactPoint& contact, const LocalGrowth& order, double local,
                                double far) noexcept;

/// Separates `amount` along `order`; returns the area separated.
double apply_local_growth(const SeparationPatch& patch, SeparationState& state,
                          const LocalGrowth& order, double amount) noexcept;

/// Room at the front outside `excluded` (may be null) as it stands now [m^2].
double front_room(const SeparationPatch& patch, const SeparationState& state,
                  const ContactRegion* excluded) noexcept;

/// Separates up to `amount` at the front outside `excluded` (may be null), nearest
/// `origin` first; returns the area separated.
double grow_nearest(const SeparationPatch& patch, SeparationState& state,
                    const Eigen::Vector3d& origin, double amount,
                    const ContactRegion* excluded) noexcept;

}  // namespace cohaptic
