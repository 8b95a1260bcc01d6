// ComplianceRowsSender: the server's record of what one client holds under compliance
// rows (compliance_rows.h), and the rows to send it with each IR. One per user and
// connection; the IRs it converts must reach that client in order and none dropped (the
// server sends them as must-arrive frames on the user's TCP connection; a client that
// still missed one refuses every later one). restart() when a new user takes the slot, or
// the user's IR moves to another body: the next IR is generation 1, every row.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/fem/compliance_source.h"
#include "common/fem/dof_map.h"
#include "common/ir/intermediate_representation.h"

namespace cohaptic {

class ComplianceRowsSender {
 public:
  /// Replaces `ir`'s M~ by the rows of L for the nodes the client does not hold yet, read
  /// from `columns` (the body's compliance, mesh node indices and `dofs`); `mesh_nodes`:
  /// the mesh node of each of ir.held_node_ids() (with B truncation these include the held
  /// nodes the IR leaves out). The client holds all of them afterwards. Throws Error if the
  /// sizes do not match.
  void convert(CondensedFemIr& ir, std::span<const int> mesh_nodes, ComplianceSource& columns,
               const DofMap& dofs);
  /// The client holds nothing (a new user of the slot, another body): the next IR starts
  /// generation 1 with every row.
  void restart();
  std::uint64_t generation() const { return generation_; }

 private:
  std::vector<std::int64_t> held_;  // node tags, in held order
  std::uint64_t generation_ = 0;
};

}  // namespace cohaptic
