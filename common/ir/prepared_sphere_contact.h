// What the client derives once per intermediate representation for the sphere contact
// model (common/contact/sphere_contact.h), beside the condensed compliance every model
// uses: the guard ring's corners that are not candidate nodes (a sphere reaching one has
// left what the IR describes); and the warm start of the per-tick contact solve, which each
// evaluator keeps in its own state.
//
// In a sphere IR every contact (row) node is a candidate for every tool, own and remote:
// the patch holds the own sphere's candidates, the nodes after it the remote spheres'.
// At most kMaxSphereCandidates of them. Units: m.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>

#include "common/ir/intermediate_representation.h"

namespace cohaptic {

constexpr int kMaxSphereCandidates = 128;  ///< contact nodes of a sphere IR
constexpr int kMaxSphereContacts = 64;     ///< the working set of one tick's contact solve (nodes)

/// The active set of the last sphere contact solve, one bit per contact node: the next
/// tick's warm start, held in the evaluator's EvaluationState. Only the path to the answer
/// depends on it, never the answer (unilateral_contact_solve.h).
class SphereWarmStart {
 public:
  bool active(int node) const noexcept;
  /// Replaces the set: `nodes[i]` is active when `active[i]` is non-zero; all others are not.
  void store(std::span<const int> nodes, std::span<const std::uint8_t> active) noexcept;

 private:
  std::array<std::uint64_t, kMaxSphereCandidates / 64> words_{};
};

struct PreparedSphereContact {
  Eigen::Matrix3Xd outside_corners;  ///< guard triangle corners that are not contact nodes [m]
};

/// Checks the sphere IR's limits (Error naming them) and finds the outside corners;
/// `tool_radius` is the own tool's [m] (the IR's envelope holds it).
PreparedSphereContact prepare_sphere_contact(const CondensedFemIr& ir, double tool_radius);

}  // namespace cohaptic
