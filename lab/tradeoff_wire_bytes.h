// TradeoffWireBytes: the bytes a trade-off run's IRs take on the wire, as the server sends
// them (server/simulation_loop.cpp): a condensed FEM IR in the compliance rows form
// (common/ir/compliance_rows.h: the rows of L for the nodes the user's client does not hold
// yet instead of M~, one ComplianceRowsSender per user) compressed in the user's IR stream
// (proto/wire/ir_stream.h), B truncation or not (a truncated IR lists the held nodes it
// leaves out); a sphere body's IR whole in the same stream; counted as the protobuf
// message's size (what the server's ir_bytes_sent counts). Bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "common/fem/compliance_source.h"
#include "common/ir/compliance_rows_sender.h"
#include "common/ir/intermediate_representation.h"
#include "common/model/elastic_body.h"
#include "proto/wire/ir_stream.h"

namespace cohaptic {

class TradeoffWireBytes {
 public:
  /// `body` and `columns` outlive this.
  TradeoffWireBytes(const ElasticBody& body, ComplianceSource& columns, std::size_t users);
  /// The wire bytes of `ir`, published to `user` (0 .. users - 1) after the IRs counted
  /// before for that user.
  std::size_t published(const IntermediateRepresentation& ir, std::size_t user);

 private:
  const ElasticBody& body_;
  ComplianceSource& columns_;
  std::vector<ComplianceRowsSender> senders_;
  std::vector<wire::IrStreamWriter> streams_;
  std::vector<bool> stream_started_;  // per user: a block sent
  std::unordered_map<std::int64_t, int> node_of_tag_;
};

}  // namespace cohaptic
