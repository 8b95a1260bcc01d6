#include "lab/tradeoff_wire_bytes.h"

#include "common/mesh/tet_mesh.h"
#include "proto/wire/ir_convert.h"

namespace cohaptic {

TradeoffWireBytes::TradeoffWireBytes(const ElasticBody& body, ComplianceSource& columns,
                                     std::size_t users)
    : body_(body),
      columns_(columns),
      senders_(users),
      streams_(users),
      stream_started_(users, false),
      node_of_tag_(node_indices_by_tag(body.mesh)) {}

std::size_t TradeoffWireBytes::published(const IntermediateRepresentation& ir, std::size_t user) {
  const auto* fem = std::get_if<CondensedFemIr>(&ir.body);
  if (!fem) return wire::to_wire(ir).ByteSizeLong();
  if (fem->sphere) {  // whole, in the stream (as the server sends it)
    const bool fresh = !stream_started_.at(user);
    stream_started_.at(user) = true;
    return streams_.at(user).compress(wire::to_wire(ir), fresh).ByteSizeLong();
  }
  IntermediateRepresentation sent = ir;
  auto& sent_fem = std::get<CondensedFemIr>(sent.body);
  std::vector<int> mesh_nodes;
  for (const std::int64_t tag : fem->held_node_ids()) mesh_nodes.push_back(node_of_tag_.at(tag));
  senders_.at(user).convert(sent_fem, mesh_nodes, columns_, body_.dofs);
  return streams_.at(user)
      .compress(wire::to_wire(sent), sent_fem.compliance_rows->generation == 1)
      .ByteSizeLong();
}

}  // namespace cohaptic
