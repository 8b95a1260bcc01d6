#include "proto/record/mcap_bytes.h"

#include <fmt/format.h>

#include <limits>

#include "common/util/error.h"

namespace cohaptic::record {
namespace {

template <typename T>
void put_le(ByteBuffer& out, T value) {
  for (std::size_t i = 0; i < sizeof(T); ++i)
    out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}

template <typename T>
T get_le(std::span<const std::uint8_t> bytes) {
  T value = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i)
    value = static_cast<T>(value | (static_cast<T>(bytes[i]) << (8 * i)));
  return value;
}

std::uint32_t length_u32(std::size_t length, std::string_view what) {
  if (length > std::numeric_limits<std::uint32_t>::max()) {
    throw Error(fmt::format("MCAP {} of {} bytes exceeds the format's 4 GiB limit", what, length));
  }
  return static_cast<std::uint32_t>(length);
}

}  // namespace

void put_u8(ByteBuffer& out, std::uint8_t value) { out.push_back(value); }
void put_u16(ByteBuffer& out, std::uint16_t value) { put_le(out, value); }
void put_u32(ByteBuffer& out, std::uint32_t value) { put_le(out, value); }
void put_u64(ByteBuffer& out, std::uint64_t value) { put_le(out, value); }

void put_bytes(ByteBuffer& out, std::span<const std::uint8_t> bytes) {
  out.insert(out.end(), bytes.begin(), bytes.end());
}

void put_string(ByteBuffer& out, std::string_view text) {
  put_u32(out, length_u32(text.size(), "string"));
  out.insert(out.end(), text.begin(), text.end());
}

void put_string_map(ByteBuffer& out, const std::map<std::string, std::string>& map) {
  std::size_t length = 0;
  for (const auto& [key, value] : map) length += 8 + key.size() + value.size();
  put_u32(out, length_u32(length, "map"));
  for (const auto& [key, value] : map) {
    put_string(out, key);
    put_string(out, value);
  }
}

std::size_t begin_record(ByteBuffer& out, std::uint8_t opcode) {
  const std::size_t start = out.size();
  put_u8(out, opcode);
  put_u64(out, 0);
  return start;
}

void end_record(ByteBuffer& out, std::size_t start) {
  const std::uint64_t length = out.size() - start - 9;
  for (std::size_t i = 0; i < 8; ++i)
    out[start + 1 + i] = static_cast<std::uint8_t>(length >> (8 * i));
}

std::span<const std::uint8_t> ByteCursor::take(std::size_t n, const char* field) {
  if (n > remaining()) {
    throw Error(fmt::format("field '{}' needs {} bytes but only {} remain in the record", field, n,
                            remaining()));
  }
  const auto out = bytes_.subspan(position_, n);
  position_ += n;
  return out;
}

std::uint8_t ByteCursor::u8(const char* field) { return take(1, field)[0]; }
std::uint16_t ByteCursor::u16(const char* field) { return get_le<std::uint16_t>(take(2, field)); }
std::uint32_t ByteCursor::u32(const char* field) { return get_le<std::uint32_t>(take(4, field)); }
std::uint64_t ByteCursor::u64(const char* field) { return get_le<std::uint64_t>(take(8, field)); }

std::string ByteCursor::string(const char* field) {
  const std::uint32_t length = u32(field);
  const auto text = take(length, field);
  return {text.begin(), text.end()};
}

std::span<const std::uint8_t> ByteCursor::bytes(std::size_t n, const char* field) {
  return take(n, field);
}

ByteCursor ByteCursor::prefixed(const char* field) {
  const std::uint32_t length = u32(field);
  return ByteCursor(take(length, field));
}

std::span<const std::uint8_t> ByteCursor::rest() { return take(remaining(), "rest"); }

std::map<std::string, std::string> read_string_map(ByteCursor& cursor, const char* field) {
  ByteCursor entries = cursor.prefixed(field);
  std::map<std::string, std::string> map;
  while (entries.remaining() > 0) {
    std::string key = entries.string(field);
    map[std::move(key)] = entries.string(field);
  }
  return map;
}

}  // namespace cohaptic::record
