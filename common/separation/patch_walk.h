// Moving a contact point over the patch: a straight walk in each triangle's plane, across
// shared edges into the neighbour, stopping at the patch rim and — for a sliding contact —
// at a crack edge (an edge between an open and a closed triangle: the paper's "the
// contact point c stops sliding if it reaches a crack edge", Sec. V.D). noexcept, no
// allocation. Units: m.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "common/separation/separation_state.h"

namespace cohaptic {

struct PatchWalk {
  enum class Stop : std::uint8_t { none, crack_edge, rim };
  int triangle = -1;
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();  ///< area coordinates on `triangle`
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    ///< [m]
  double travelled = 0;                               ///< along the surface [m]
  Stop stop = Stop::none;
};

/// Walks `distance` from the point with area coordinates `weights` on `triangle`, along
/// `direction` projected on each triangle's plane.
PatchWalk walk_on_patch(const SeparationPatch& patch, const SeparationState& state, int triangle,
                        const Eigen::Vector3d& weights, const Eigen::Vector3d& direction,
                        double distance, bool stop_at_crack_edges) noexcept;

}  // namespace cohaptic
