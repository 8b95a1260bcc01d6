#include "support/mcap_layout.h"

#include <fstream>
#include <iterator>

namespace cohaptic::testing {
namespace {

constexpr std::uint8_t kFooter = 0x02, kSchema = 0x03, kChannel = 0x04, kMessage = 0x05,
                       kChunk = 0x06, kMessageIndex = 0x07, kStatistics = 0x0B, kDataEnd = 0x0F;

void put_le(Bytes& out, std::uint64_t value, int width) {
  for (int i = 0; i < width; ++i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}

void put_range(Bytes& out, const Bytes& from, std::size_t begin, std::size_t end) {
  out.insert(out.end(), from.begin() + static_cast<std::ptrdiff_t>(begin),
             from.begin() + static_cast<std::ptrdiff_t>(end));
}

}  // namespace

const std::string kMcapMagicText("\x89MCAP0\r\n", 8);

Bytes read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_bytes(const std::filesystem::path& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

std::uint64_t le(const Bytes& b, std::size_t at, int width) {
  std::uint64_t value = 0;
  for (int i = width - 1; i >= 0; --i)
    value = (value << 8) | b.at(at + static_cast<std::size_t>(i));
  return value;
}
std::uint16_t le16(const Bytes& b, std::size_t at) {
  return static_cast<std::uint16_t>(le(b, at, 2));
}
std::uint32_t le32(const Bytes& b, std::size_t at) {
  return static_cast<std::uint32_t>(le(b, at, 4));
}
std::uint64_t le64(const Bytes& b, std::size_t at) { return le(b, at, 8); }
std::string text(const Bytes& b, std::size_t at, std::size_t n) {
  return std::string(reinterpret_cast<const char*>(b.data() + at), n);
}

std::uint32_t reference_crc(const Bytes& b, std::size_t begin, std::size_t end) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = begin; i < end; ++i) {
    c ^= b[i];
    for (int bit = 0; bit < 8; ++bit) c = (c & 1u) ? (c >> 1) ^ 0xEDB88320u : c >> 1;
  }
  return ~c;
}

std::vector<RawRecord> records_between(const Bytes& b, std::size_t begin, std::size_t end) {
  std::vector<RawRecord> records;
  for (std::size_t at = begin; at + 9 <= end;) {
    const RawRecord r{at, b[at], le64(b, at + 1)};
    if (r.length > end - at - 9) break;
    records.push_back(r);
    at = r.end();
  }
  return records;
}

std::vector<RawRecord> walk(const Bytes& b) {
  std::vector<RawRecord> records = records_between(b, 8, b.size());
  for (std::size_t i = 0; i < records.size(); ++i)
    if (records[i].opcode == kFooter) records.resize(i + 1);
  return records;
}

RawChunk read_chunk(const Bytes& b, const RawRecord& chunk) {
  RawChunk c{};
  std::size_t at = chunk.content();
  c.message_start_time = le64(b, at);
  c.message_end_time = le64(b, at + 8);
  c.uncompressed_size = le64(b, at + 16);
  c.uncompressed_crc = le32(b, at + 24);
  const std::uint32_t compression_length = le32(b, at + 28);
  c.compression = text(b, at + 32, compression_length);
  at += 32 + compression_length;
  c.records_begin = at + 8;
  c.records_end = c.records_begin + static_cast<std::size_t>(le64(b, at));
  return c;
}

std::vector<RawMessage> messages_of(const Bytes& b) {
  std::vector<RawMessage> messages;
  for (const RawRecord& r : walk(b)) {
    if (r.opcode == kDataEnd) break;
    if (r.opcode == kMessage) messages.push_back({r, r.end()});
    if (r.opcode != kChunk) continue;
    const RawChunk chunk = read_chunk(b, r);
    for (const RawRecord& inner : records_between(b, chunk.records_begin, chunk.records_end))
      if (inner.opcode == kMessage) messages.push_back({inner, r.end()});
  }
  return messages;
}

Bytes unchunked(const Bytes& chunked) {
  const std::vector<RawRecord> records = walk(chunked);
  Bytes out;
  put_range(out, chunked, 0, records.at(0).end());  // the magic and the Header
  std::size_t r = 1;
  for (; r < records.size() && records[r].opcode != kDataEnd; ++r) {
    if (records[r].opcode == kChunk) {
      const RawChunk chunk = read_chunk(chunked, records[r]);
      put_range(out, chunked, chunk.records_begin, chunk.records_end);
    } else if (records[r].opcode != kMessageIndex) {
      put_range(out, chunked, records[r].offset, records[r].end());
    }
  }
  const std::uint32_t data_crc = reference_crc(out, 0, out.size());
  out.push_back(kDataEnd);
  put_le(out, 4, 8);
  put_le(out, data_crc, 4);

  const std::size_t summary_start = out.size();
  for (++r; r < records.size(); ++r) {
    const RawRecord& record = records[r];
    if (record.opcode != kSchema && record.opcode != kChannel && record.opcode != kStatistics)
      continue;
    const std::size_t at = out.size();
    put_range(out, chunked, record.offset, record.end());
    if (record.opcode == kStatistics)
      for (std::size_t i = 0; i < 4; ++i) out[at + 9 + 22 + i] = 0;  // chunk_count
  }
  out.push_back(kFooter);
  put_le(out, 20, 8);
  put_le(out, summary_start, 8);
  put_le(out, 0, 8);  // no Summary Offsets
  put_le(out, reference_crc(out, summary_start, out.size()), 4);
  out.insert(out.end(), kMcapMagicText.begin(), kMcapMagicText.end());
  return out;
}

}  // namespace cohaptic::testing
