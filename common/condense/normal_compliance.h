// NormalCompliance: the sphere contact model's normal compliance between candidate nodes,
// kept by the server while the candidates and the held boundary nodes B change.
//
// For candidate nodes each pushed along a unit direction n (a sphere's: the node's inward
// normal; an obstacle's: the obstacle's normal, common/contact/sphere_contact.h), the
// compliance between their pushes with B held at its displacement u_B:
//   W_ab = n_a^T L~_ab n_b,  L~ = L_CC - L_CB L_BB^-1 L_BC,
// so W = W0 - P^T Q with W0_ab = n_a^T L_ab n_b, P = L_BC N (B's free dofs x candidates)
// and Q = L_BB^-1 P; and each candidate's free clearance q0_a = n_a . u0_a = (Q^T u_B)_a,
// u0 the displacement that B's held displacement alone gives. A candidate's row of W is
// one number per other candidate where M~ would hold nine per pair of nodes, and none of
// it depends on where the tools are, only on each node's direction.
//
// Candidates live in slots: a node keeps its slot while it stays a candidate along the same
// direction, and a leaving node's slot is reused, so W's entries and the indices of a contact solve
// over the slots (incremental_contact_solve.h) stay put while the set changes. A joining node costs
// one column solve (cached in ComplianceColumns) and its row of W0, P and Q, O(|C| + |B|^2); a
// change of B recomputes P, Q and W, O(|B|^2 |C| + |B| |C|^2), keeping W0; a change of u_B only q0,
// O(|B| |C|). W is exactly symmetric (each pair is computed once). The slots' capacity doubles when
// they run out, copying W0, W, P and Q: a step that has to grow a large capacity stalls (the first
// wide press against an obstacle, say), so the owner gives, at construction, as many slots as
// candidates can ever be, up to kMaxInitialCapacity. Units: m/N, m. Not thread-safe: the simulation
// loop owns it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "common/condense/incremental_condensation.h"
#include "common/fem/compliance.h"
#include "common/fem/dof_map.h"

namespace cohaptic {

class NormalCompliance {
 public:
  /// Slots made at construction at most: W0, W and a contact solve's factor are each this
  /// many squared doubles (134 MB at 4096).
  static constexpr Eigen::Index kMaxInitialCapacity = 4096;

  /// `columns` and `dofs` must outlive it (a copy shares them: they do not change); every
  /// candidate and every node of B must be a row node of `columns`. `expected_candidates`:
  /// how many candidates there may be at once (the capacity made now: at least 64, at most
  /// kMaxInitialCapacity).
  NormalCompliance(ComplianceColumns& columns, const DofMap& dofs,
                   Eigen::Index expected_candidates = 0);

  /// The candidates become `nodes` (each once, none in B), each pushed along its column of
  /// `directions` (per volume node), under the held set of `condensation` held at
  /// `boundary_displacement` (free dofs of B in its order). A node whose direction changed
  /// since it took its slot leaves it and joins again. Returns whether W changed between
  /// slots that stay (B changed): a factor kept over them is void.
  bool update(std::span<const int> nodes, const Eigen::Matrix3Xd& directions,
              const IncrementalCondensation& condensation,
              const Eigen::VectorXd& boundary_displacement);

  /// Slots [0, slot_count()) hold a candidate or are free; W is slot_count() square.
  int slot_count() const { return static_cast<int>(node_of_slot_.size()); }
  /// The slots' capacity: W's rows (a contact solve over the slots needs this many).
  Eigen::Index capacity() const { return w_.rows(); }
  int node_of(int slot) const {
    return node_of_slot_[static_cast<std::size_t>(slot)];
  }                             ///< -1: free
  int slot_of(int node) const;  ///< -1 if not a candidate
  /// The direction the slot's node was taken with.
  Eigen::Vector3d normal(int slot) const { return slot_direction_.col(slot); }
  /// Whether `node` is a candidate taken along `direction` (false: it is none, or an update
  /// with that direction moves it to a new slot).
  bool current(int node, const Eigen::Vector3d& direction) const;

  /// W over the slots (capacity() square; free slots' rows and columns are zero but for a
  /// unit diagonal) [m/N].
  const Eigen::MatrixXd& w() const { return w_; }
  /// q0 per slot (capacity() entries, zero for free slots) [m].
  const Eigen::VectorXd& free_clearance() const { return free_clearance_; }
  /// Per slot: 1 if its row of W has no negative entry (capacity() entries; a row may be
  /// flagged 0 that no longer has one, since a slot left).
  const std::vector<std::uint8_t>& nonnegative_rows() const { return nonnegative_; }

 private:
  void grow(Eigen::Index capacity);
  /// P for the nodes in `slots`, and the rows and columns of W0 of those in `joined`.
  void add_columns(std::span<const int> slots, std::span<const int> joined);
  /// W and Q for the pairs with a slot of `slots` (all pairs: every slot), from W0 and P,
  /// Q over B of `condensation`.
  void condense(std::span<const int> slots, const IncrementalCondensation& condensation);
  /// The rows without a negative entry: all of them anew (`all`), or after `joined` slots.
  void find_nonnegative_rows(std::span<const int> joined, bool all);

  ComplianceColumns& columns_;
  const DofMap& dofs_;
  Eigen::Matrix3Xd slot_direction_;  // per slot: its node's direction when it joined
  std::vector<int> node_of_slot_;
  std::vector<int> slot_of_node_;  // per volume node
  std::vector<int> free_slots_;
  std::vector<int> boundary_;  // B as of the last update
  std::vector<int> boundary_dofs_;
  Eigen::MatrixXd w0_, w_;  // capacity square
  Eigen::MatrixXd p_, q_;   // B's free dofs x capacity
  Eigen::VectorXd free_clearance_;
  std::vector<std::uint8_t> nonnegative_;
};

}  // namespace cohaptic
