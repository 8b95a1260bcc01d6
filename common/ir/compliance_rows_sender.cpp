#include "common/ir/compliance_rows_sender.h"

#include <fmt/format.h>

#include <algorithm>
#include <unordered_map>

#include "common/condense/dof_blocks.h"
#include "common/util/error.h"

namespace cohaptic {

void ComplianceRowsSender::convert(CondensedFemIr& ir, std::span<const int> mesh_nodes,
                                   ComplianceSource& columns, const DofMap& dofs) {
  const std::vector<std::int64_t> ir_held = ir.held_node_ids();
  if (mesh_nodes.size() != ir_held.size())
    throw Error(fmt::format("compliance rows: {} mesh nodes for an IR holding {} nodes",
                            mesh_nodes.size(), ir_held.size()));
  const std::vector<int> ir_dofs = free_dofs_of_nodes(dofs, mesh_nodes.first(ir.node_ids.size()));
  if (ir.m_tilde.cols() != static_cast<Eigen::Index>(ir_dofs.size()))
    throw Error(fmt::format("compliance rows: M~ has {} columns, the IR's nodes {} free dofs",
                            ir.m_tilde.cols(), ir_dofs.size()));
  std::unordered_map<std::int64_t, int> mesh_of_tag;
  for (std::size_t i = 0; i < mesh_nodes.size(); ++i)
    mesh_of_tag.emplace(ir_held[i], mesh_nodes[i]);
  const std::vector<std::int64_t> after = held_after(held_, ir_held);
  // held_after puts the nodes still held first.
  const auto kept = static_cast<std::size_t>(std::count_if(
      held_.begin(), held_.end(), [&](std::int64_t tag) { return mesh_of_tag.contains(tag); }));
  std::vector<int> after_mesh;
  for (const std::int64_t tag : after) after_mesh.push_back(mesh_of_tag.at(tag));
  const std::vector<int> added_dofs =
      free_dofs_of_nodes(dofs, std::span<const int>(after_mesh).subspan(kept));
  const std::vector<int> after_dofs = free_dofs_of_nodes(dofs, after_mesh);
  ir.compliance_rows =
      ComplianceRows{++generation_, gather_compliance(columns, added_dofs, after_dofs)};
  ir.m_tilde.resize(0, 0);
  held_ = after;
}

void ComplianceRowsSender::restart() {
  held_.clear();
  generation_ = 0;
}

}  // namespace cohaptic
