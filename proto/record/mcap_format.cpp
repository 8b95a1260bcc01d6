#include "proto/record/mcap_format.h"

#include <fmt/format.h>

namespace cohaptic::record {

std::string mcap_opcode_name(std::uint8_t op) {
  switch (op) {
    case opcode::kHeader:
      return "Header";
    case opcode::kFooter:
      return "Footer";
    case opcode::kSchema:
      return "Schema";
    case opcode::kChannel:
      return "Channel";
    case opcode::kMessage:
      return "Message";
    case opcode::kChunk:
      return "Chunk";
    case opcode::kMessageIndex:
      return "Message Index";
    case opcode::kChunkIndex:
      return "Chunk Index";
    case opcode::kAttachment:
      return "Attachment";
    case opcode::kAttachmentIndex:
      return "Attachment Index";
    case opcode::kStatistics:
      return "Statistics";
    case opcode::kMetadata:
      return "Metadata";
    case opcode::kMetadataIndex:
      return "Metadata Index";
    case opcode::kSummaryOffset:
      return "Summary Offset";
    case opcode::kDataEnd:
      return "Data End";
    default:
      return fmt::format("unknown (0x{:02X})", op);
  }
}

}  // namespace cohaptic::record
