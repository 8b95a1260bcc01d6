// MCAP files taken apart byte by byte for tests, written here from the spec
// (https://mcap.dev/spec) and independent of proto/record/: little-endian fields, the CRC-32
// by its bitwise definition, walking records, the fields of a Chunk, and an unchunked copy
// of a chunked file (the layout of recordings written without chunks). Offsets are byte
// offsets from the start of the file; nothing here throws on a malformed file, the walks
// stop where records stop being complete.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace cohaptic::testing {

using Bytes = std::vector<std::uint8_t>;

Bytes read_bytes(const std::filesystem::path& path);
void write_bytes(const std::filesystem::path& path, const Bytes& bytes);

/// The unsigned little-endian integer of `width` bytes at `at` (bounds checked).
std::uint64_t le(const Bytes& b, std::size_t at, int width);
std::uint16_t le16(const Bytes& b, std::size_t at);
std::uint32_t le32(const Bytes& b, std::size_t at);
std::uint64_t le64(const Bytes& b, std::size_t at);
std::string text(const Bytes& b, std::size_t at, std::size_t n);

/// CRC-32 (IEEE, as MCAP and zlib use it) of b[begin, end), bit by bit as the definition goes.
std::uint32_t reference_crc(const Bytes& b, std::size_t begin, std::size_t end);

/// 0x89 "MCAP0" "\r\n".
extern const std::string kMcapMagicText;

struct RawRecord {
  std::size_t offset;
  std::uint8_t opcode;
  std::uint64_t length;  ///< of its content
  std::size_t content() const { return offset + 9; }
  std::size_t end() const { return offset + 9 + static_cast<std::size_t>(length); }
};

/// The complete records laid end to end in b[begin, end).
std::vector<RawRecord> records_between(const Bytes& b, std::size_t begin, std::size_t end);
/// The records after the opening magic, up to and including the Footer (or the last complete one).
std::vector<RawRecord> walk(const Bytes& b);

/// A Chunk record's fields; its records lie in [records_begin, records_end).
struct RawChunk {
  std::uint64_t message_start_time;
  std::uint64_t message_end_time;
  std::uint64_t uncompressed_size;
  std::uint32_t uncompressed_crc;
  std::string compression;
  std::size_t records_begin;
  std::size_t records_end;
};
RawChunk read_chunk(const Bytes& b, const RawRecord& chunk);

/// A Message record of the data section, and the end of the top-level record that holds it
/// (its Chunk, or itself outside chunks): a cut at or after that end leaves it readable.
struct RawMessage {
  RawRecord record;
  std::size_t readable_from;
};
/// Every Message record of the data section, in file order.
std::vector<RawMessage> messages_of(const Bytes& b);

/// A complete chunked file rewritten without chunks: the records inside each Chunk in their
/// place, no Message Index, Data End with the new data section's CRC, then a summary of the
/// Schema, Channel and Statistics records (chunk_count 0), no Summary Offsets, the Footer
/// with the summary CRC, and the magic.
Bytes unchunked(const Bytes& chunked);

}  // namespace cohaptic::testing
