// The MCAP records McapReader hands out, as plain values (https://mcap.dev/spec#records).
// Times are u64 nanoseconds since the recording's epoch; ids are the file's own (a schema
// id is never 0; a channel's schema_id of 0 means it has no schema).
#pragma once

#include <compare>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace cohaptic::record {

struct McapSchema {
  std::uint16_t id = 0;
  std::string name;      ///< for protobuf: the message's full name
  std::string encoding;  ///< e.g. "protobuf"; empty: no schema
  std::string data;      ///< bytes in `encoding`'s format (protobuf: a FileDescriptorSet)
  bool operator==(const McapSchema&) const = default;
};

struct McapChannel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;  ///< e.g. "protobuf"
  std::map<std::string, std::string> metadata;
  bool operator==(const McapChannel&) const = default;
};

struct McapMessage {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time_ns = 0;
  std::uint64_t publish_time_ns = 0;
  std::vector<std::uint8_t> data;  ///< encoded per the channel's message_encoding
  bool operator==(const McapMessage&) const = default;
};

/// What the CRCs of a file vouch for among the messages McapReader has yielded so far. A CRC
/// counts once the reader has checked it: a Chunk's before any of its messages is yielded,
/// Data End's (over the whole data section) once the reader reaches it. A file cut short has
/// no Data End: only its chunks' CRCs cover it, and its messages outside chunks are unchecked.
struct McapCrcCoverage {
  std::uint64_t checked_messages = 0;    ///< covered by a CRC that matched
  std::uint64_t unchecked_messages = 0;  ///< covered by none (yet)
  /// File offset just past the last record whose CRC matched (a Chunk, or Data End); 0: none.
  std::uint64_t checked_through_offset = 0;
  /// The latest log time among the checked messages (ns); absent when there are none.
  std::optional<std::uint64_t> checked_end_time_ns;
  bool operator==(const McapCrcCoverage&) const = default;
};

/// The Statistics record of a file's summary section.
struct McapStatistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time_ns = 0;  ///< earliest log time; 0 without messages
  std::uint64_t message_end_time_ns = 0;    ///< latest log time; 0 without messages
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
  bool operator==(const McapStatistics&) const = default;
};

}  // namespace cohaptic::record
