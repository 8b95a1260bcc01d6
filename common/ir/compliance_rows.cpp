#include "common/ir/compliance_rows.h"

#include <unordered_set>

namespace cohaptic {

std::vector<std::int64_t> held_after(std::span<const std::int64_t> held,
                                     std::span<const std::int64_t> ir_nodes) {
  const std::unordered_set<std::int64_t> in_ir(ir_nodes.begin(), ir_nodes.end());
  std::vector<std::int64_t> after;
  after.reserve(ir_nodes.size());
  for (const std::int64_t node : held)
    if (in_ir.contains(node)) after.push_back(node);
  const std::unordered_set<std::int64_t> kept(after.begin(), after.end());
  for (const std::int64_t node : ir_nodes)
    if (!kept.contains(node)) after.push_back(node);
  return after;
}

}  // namespace cohaptic
