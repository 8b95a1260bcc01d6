// Little-endian serialization of MCAP fields (https://mcap.dev/spec#serialization):
// appending to a byte buffer (the writer) and reading from a bounded byte range (the
// reader). Integers are little-endian whatever the host; a String or a length-prefixed
// Bytes field carries a u32 byte length; a Map carries a u32 byte length of its entries.
//
// ByteCursor never reads outside its range: a field that would run past the end throws
// cohaptic::Error saying which field, so that a record whose declared length is too short
// for its fields is reported as malformed rather than read out of bounds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace cohaptic::record {

using ByteBuffer = std::vector<std::uint8_t>;

void put_u8(ByteBuffer& out, std::uint8_t value);
void put_u16(ByteBuffer& out, std::uint16_t value);
void put_u32(ByteBuffer& out, std::uint32_t value);
void put_u64(ByteBuffer& out, std::uint64_t value);
/// Raw bytes, no length prefix.
void put_bytes(ByteBuffer& out, std::span<const std::uint8_t> bytes);
/// u32 length + bytes; throws cohaptic::Error if longer than 2^32 - 1 bytes.
void put_string(ByteBuffer& out, std::string_view text);
/// Map<string, string>: u32 byte length of the entries, then key, value, ... (sorted by key).
void put_string_map(ByteBuffer& out, const std::map<std::string, std::string>& map);

/// Starts a record: writes the opcode and a placeholder length; returns where the record
/// starts, to be passed to end_record() once its content is appended.
std::size_t begin_record(ByteBuffer& out, std::uint8_t opcode);
/// Fills in the content length of the record started at `start`.
void end_record(ByteBuffer& out, std::size_t start);

/// Reads fields in order from a byte range; each read advances the cursor.
class ByteCursor {
 public:
  explicit ByteCursor(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}

  std::uint8_t u8(const char* field);
  std::uint16_t u16(const char* field);
  std::uint32_t u32(const char* field);
  std::uint64_t u64(const char* field);
  /// u32 length + bytes.
  std::string string(const char* field);
  /// The next n bytes.
  std::span<const std::uint8_t> bytes(std::size_t n, const char* field);
  /// A cursor over a u32 length-prefixed range (a Map or an Array), advancing past it.
  ByteCursor prefixed(const char* field);
  /// Everything not read yet (the cursor moves to the end).
  std::span<const std::uint8_t> rest();
  std::size_t remaining() const { return bytes_.size() - position_; }

 private:
  std::span<const std::uint8_t> take(std::size_t n, const char* field);
  std::span<const std::uint8_t> bytes_;
  std::size_t position_ = 0;
};

/// Reads a Map<string, string>.
std::map<std::string, std::string> read_string_map(ByteCursor& cursor, const char* field);

}  // namespace cohaptic::record
