// ClientCondensation: on a haptic client's I/O thread, turns a condensed FEM IR that came
// with compliance rows (compliance_rows.h) into the IR with its M~, as the server would
// have sent it (equal to rounding: the same code, another order of joins).
//
// It keeps the compliance L_HH of the held nodes H (HeldCompliance, dense, free dofs only)
// and an IncrementalCondensation over it, the server's class: per IR, the nodes that left
// H are forgotten, the added rows appended, B set to the IR's boundary nodes (with B
// truncation also the held nodes the IR leaves out, whose columns of M_CB are then dropped:
// the server's choice, never re-decided here) and M~ formed for its contact nodes, then
// reordered to the IR's columns. Nodes get small indices of
// their own here (reused once forgotten), so the DofMap stays as small as H.
//
// An IR it cannot complete (a generation that does not follow the one held, a row count
// that does not match the added nodes' free dofs, non-finite rows, a held node whose
// fixed axes changed, a node listed twice, also as kept and truncated) throws Error saying which,
// and changes nothing: the next IR that follows the held generation still completes exactly. Units:
// m/N, N/m. Not thread-safe: one I/O thread owns it.
#pragma once

#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "common/condense/incremental_condensation.h"
#include "common/fem/compliance_source.h"
#include "common/ir/intermediate_representation.h"

namespace cohaptic {

/// L over the free dofs of the held nodes, by node index (3 * index + axis dofs).
class HeldCompliance final : public ComplianceSource {
 public:
  /// Every node asked for must be held.
  void compute_columns(const std::vector<int>& nodes) override;
  Eigen::MatrixXd dof_block(std::span<const int> row_dofs, std::span<const int> col_dofs) override;

  const std::vector<int>& nodes() const { return nodes_; }
  /// Drops the nodes whose `keep` entry (per held node, in held order) is false.
  void keep_only(const std::vector<bool>& keep);
  /// Appends `added` nodes (their free dofs under `dofs`) with `rows`: L[added free dofs,
  /// free dofs of every node held after, the added last].
  void append(const std::vector<int>& added, const Eigen::MatrixXd& rows, const DofMap& dofs);
  void clear();

 private:
  int position_of(int dof) const;  ///< row of L, or throws Error
  std::vector<int> nodes_;         ///< held node indices, in held order
  std::vector<int> offset_;        ///< per node index: its first row in l_, or -1
  std::vector<AxisMask> fixed_;    ///< per node index, as appended
  Eigen::MatrixXd l_;              ///< L_HH over free dofs, held order
};

class ClientCondensation {
 public:
  ClientCondensation();
  // The condensation refers to the members: not copied, not moved.
  ClientCondensation(const ClientCondensation&) = delete;
  ClientCondensation& operator=(const ClientCondensation&) = delete;

  /// Fills `ir.m_tilde` from `ir.compliance_rows` and clears them. Nothing to do for an IR
  /// that carries M~ itself. Throws Error (changing nothing) if the rows cannot be applied.
  void complete(CondensedFemIr& ir);
  /// The generation of the held set (0: nothing held yet).
  std::uint64_t generation() const { return generation_; }
  std::size_t held_node_count() const { return held_tags_.size(); }

 private:
  /// A node index for `tag` (a forgotten one reused, else the next), its fixed axes set in
  /// `fixed_axes` (the dof map's, rebuilt from it once all new nodes have theirs).
  int index_for(std::int64_t tag, AxisMask fixed, std::vector<AxisMask>& fixed_axes);
  void forget_all();

  DofMap dofs_;  // by node index; the condensation reads it
  HeldCompliance held_;
  std::unique_ptr<IncrementalCondensation> condensation_;
  std::vector<std::int64_t> held_tags_;  // in held order
  std::unordered_map<std::int64_t, int> index_of_tag_;
  std::vector<int> free_indices_;
  std::uint64_t generation_ = 0;
};

}  // namespace cohaptic
