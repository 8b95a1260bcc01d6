// Compliance rows: a condensed FEM IR sent without its M~. The
// client keeps the compliance block L_HH of the nodes it holds (H: the nodes of the last
// IR it took) and condenses it itself, with the server's own code (common/condense), so
// the server sends only the rows of L for the nodes H gains.
//
// The rule both sides follow, for an IR whose nodes are A (its node_ids, then with B
// truncation its truncated_node_ids: held nodes whose columns M~ leaves out, which the
// client holds and condenses over all the same, dropping their columns afterwards; the
// server decides which are left out and says so, the client never re-decides):
//   - H after the IR = the nodes of H still in A, in H's order, then A's other nodes (the
//     "added" ones) in A's order (held_after below); nodes of H not in A are forgotten;
//   - `rows` = L[free dofs of the added nodes, free dofs of H after], dofs node by node,
//     axes x, y, z, fixed axes left out: its last columns are the added block itself;
//   - `generation` counts the IRs sent this way on one connection, from 1; the client must
//     hold generation - 1's H (generation 1: a fresh start, whatever it held before).
//     An IR whose generation does not follow is refused, never evaluated.
// The rows travel in f64 whatever the IR's precision. Units: L in m/N.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

namespace cohaptic {

struct ComplianceRows {
  std::uint64_t generation = 0;  ///< >= 1
  Eigen::MatrixXd rows;          ///< free dofs of the added nodes x free dofs of H after
};

/// The nodes held after an IR with nodes `ir_nodes`, given those held before (the rule above).
std::vector<std::int64_t> held_after(std::span<const std::int64_t> held,
                                     std::span<const std::int64_t> ir_nodes);

}  // namespace cohaptic
