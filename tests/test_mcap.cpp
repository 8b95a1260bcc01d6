// Recordings (proto/record/): the MCAP writer and reader. A round trip of thousands of
// protobuf messages in chunks; the bytes on disk (chunks and their CRCs, Message and Chunk
// Indexes, summary, footer) checked field by field against the spec with a parser and a CRC
// independent of the library (tests/support/mcap_layout.h); the protobuf schema decoding a
// recorded message through DynamicMessageFactory; truncation at thousands of cut points of
// a chunked file and of its unchunked copy, with the messages each CRC covers; a writer
// killed mid-session (fork + SIGKILL / _exit); write errors (/dev/full, a file size limit
// hit mid-session); damaged chunks and other files the reader must reject or skip over;
// and the official TypeScript reader (@mcap/core) reading our files, through their indexes
// too, and refusing the damaged ones (tests/support/mcap_check.mjs).
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <google/protobuf/api.pb.h>
#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>
#include <google/protobuf/dynamic_message.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "common/util/error.h"
#include "proto/record/crc32.h"
#include "proto/record/mcap_reader.h"
#include "proto/record/mcap_writer.h"
#include "proto/record/protobuf_schema.h"
#include "support/mcap_layout.h"
#include "support/process.h"
#include "support/test_meshes.h"

namespace cohaptic::record {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

using Bytes = testing::Bytes;
using testing::le16;
using testing::le32;
using testing::le64;
using testing::RawChunk;
using testing::RawRecord;
using testing::read_bytes;
using testing::read_chunk;
using testing::reference_crc;
using testing::text;
using testing::walk;
using testing::write_bytes;
const std::string& kMagic = testing::kMcapMagicText;

// Appends MCAP fields for hand-made files.
struct Builder {
  Bytes out;
  Builder& u8(std::uint8_t v) {
    out.push_back(v);
    return *this;
  }
  Builder& uint(std::uint64_t v, int width) {
    for (int i = 0; i < width; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    return *this;
  }
  Builder& str(const std::string& s) {
    uint(s.size(), 4);
    out.insert(out.end(), s.begin(), s.end());
    return *this;
  }
  Builder& magic() {
    out.insert(out.end(), kMagic.begin(), kMagic.end());
    return *this;
  }
  Builder& record(std::uint8_t opcode, const Bytes& content) {
    u8(opcode).uint(content.size(), 8);
    out.insert(out.end(), content.begin(), content.end());
    return *this;
  }
};

// ---- the recorded session: three protobuf types on three channels ----

wire::ToolSample tool_sample(std::uint32_t i) {
  wire::ToolSample t;
  t.set_user(i % 3);
  t.set_sample_time_ns(static_cast<std::int64_t>(i) * 1'000'000);
  t.mutable_position()->set_x(0.001 * i);
  t.mutable_position()->set_y(-0.002 * i);
  t.mutable_position()->set_z(std::sin(static_cast<double>(i)));
  t.set_valid(i % 7 != 0);
  t.set_buttons(i % 4);
  return t;
}

wire::ForceSample force_sample(std::uint32_t i) {
  wire::ForceSample f;
  f.set_user(i % 2);
  f.mutable_force()->set_x(0.5 * i);
  f.mutable_force()->set_y(1.0 / (1.0 + i));
  f.mutable_force()->set_z(-3.25);
  f.set_tool_time_ns(static_cast<std::int64_t>(i) * 1'000'000 - 17);
  f.set_ir_epoch(i / 10);
  f.set_flags(i % 5);
  return f;
}

wire::Datagram datagram(std::uint32_t i) {
  wire::Datagram d;
  d.mutable_header()->set_protocol_version(1);
  d.mutable_header()->set_session(0x5e55'1000'0001);
  d.mutable_header()->set_sender(1 + i % 2);
  d.mutable_header()->set_sequence(i);
  d.mutable_header()->set_sender_time_ns(static_cast<std::int64_t>(i) * 999'000);
  if (i % 2 == 0) {
    *d.mutable_tool() = tool_sample(i);
  } else {
    *d.mutable_force() = force_sample(i);
  }
  return d;
}

Bytes serialized(const google::protobuf::MessageLite& message) {
  Bytes out(message.ByteSizeLong());
  EXPECT_TRUE(message.SerializeToArray(out.data(), static_cast<int>(out.size())));
  return out;
}

struct Channels {
  std::uint16_t tool = 0;
  std::uint16_t datagram = 0;
  std::uint16_t force = 0;
};

const std::map<std::string, std::string> kToolMetadata = {{"user", "0"}, {"units", "m, ns"}};

Channels open_channels(McapWriter& writer) {
  const std::uint16_t tool_schema = writer.add_protobuf_schema(wire::ToolSample::descriptor());
  const std::uint16_t datagram_schema = writer.add_protobuf_schema(wire::Datagram::descriptor());
  const std::uint16_t force_schema = writer.add_protobuf_schema(wire::ForceSample::descriptor());
  Channels c;
  c.tool = writer.add_channel(tool_schema, "/user0/tool", "protobuf", kToolMetadata);
  c.datagram = writer.add_channel(datagram_schema, "/udp/received");
  c.force = writer.add_channel(force_schema, "/user0/force");
  return c;
}

constexpr std::uint64_t kEpochNs = 1'700'000'000'000'000'000ull;

// Message i of the session, as it should come back.
McapMessage expected_message(const Channels& c, std::uint32_t i) {
  McapMessage m;
  m.sequence = i;
  m.log_time_ns = kEpochNs + std::uint64_t{i} * 1'000'000;
  m.publish_time_ns = m.log_time_ns - 250'000;
  switch (i % 3) {
    case 0:
      m.channel_id = c.tool;
      m.data = serialized(tool_sample(i));
      break;
    case 1:
      m.channel_id = c.datagram;
      m.data = serialized(datagram(i));
      break;
    default:
      m.channel_id = c.force;
      m.data = serialized(force_sample(i));
      break;
  }
  return m;
}

// Writes messages [first, first + count); ToolSample by the protobuf overload, the others as bytes.
void write_messages(McapWriter& writer, const Channels& c, std::uint32_t first,
                    std::uint32_t count) {
  for (std::uint32_t i = first; i < first + count; ++i) {
    const McapMessage m = expected_message(c, i);
    if (i % 3 == 0) {
      writer.write(m.channel_id, m.sequence, m.log_time_ns, m.publish_time_ns, tool_sample(i));
    } else {
      writer.write(m.channel_id, m.sequence, m.log_time_ns, m.publish_time_ns, m.data);
    }
  }
}

// Chunks of about 4 kB (some 50 messages), flushed by size only: where they end does not
// depend on timing.
const McapWriterOptions kSmallChunks{std::chrono::hours(1), 4096};

Channels record_session(const fs::path& path, std::uint32_t count,
                        McapWriterOptions options = kSmallChunks) {
  McapWriter writer(path, options);
  const Channels c = open_channels(writer);
  write_messages(writer, c, 0, count);
  writer.close();
  return c;
}

std::vector<McapMessage> read_all(McapReader& reader) {
  std::vector<McapMessage> out;
  while (auto m = reader.next()) out.push_back(std::move(*m));
  return out;
}

// Whether `what()` of the exception thrown by f contains every one of `parts`.
template <typename F>
void expect_error(F&& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no cohaptic::Error thrown";
  } catch (const Error& e) {
    for (const auto& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

// ---- CRC ----

TEST(McapCrc32, MatchesTheStandardCheckValueAndTheBitwiseDefinition) {
  const std::string check = "123456789";
  EXPECT_EQ(crc32({reinterpret_cast<const std::uint8_t*>(check.data()), check.size()}),
            0xCBF43926u);
  EXPECT_EQ(crc32({}), 0u);
  std::mt19937 rng(5);
  Bytes data(10007);
  for (auto& b : data) b = static_cast<std::uint8_t>(rng());
  Crc32 pieces;
  for (std::size_t at = 0; at < data.size();) {
    const std::size_t n = std::min<std::size_t>(rng() % 13, data.size() - at);
    pieces.update(std::span<const std::uint8_t>(data).subspan(at, n));
    at += n;
  }
  EXPECT_EQ(pieces.value(), reference_crc(data, 0, data.size()));
  EXPECT_EQ(crc32(data), reference_crc(data, 0, data.size()));
}

// ---- round trip ----

TEST(McapRoundTrip, SchemasChannelsAndThousandsOfMessages) {
  const fs::path dir = testing::scratch_directory("mcap-roundtrip");
  const fs::path file = dir / "session.mcap";
  constexpr std::uint32_t kCount = 6000;
  const Channels c = record_session(file, kCount);

  McapReader reader(file);
  EXPECT_EQ(reader.profile(), "");
  EXPECT_EQ(reader.library(), "cohaptic");
  std::map<std::uint16_t, std::uint64_t> per_channel;
  std::uint32_t i = 0;
  std::uint32_t tools = 0;
  while (auto m = reader.next()) {
    ASSERT_LT(i, kCount);
    ASSERT_EQ(*m, expected_message(c, i)) << "message " << i;
    ++per_channel[m->channel_id];
    if (m->channel_id == c.tool) {
      const auto tool = reader.parse<wire::ToolSample>(*m);
      ASSERT_TRUE(tool.has_value());
      EXPECT_EQ(tool->SerializeAsString(), tool_sample(i).SerializeAsString());
      EXPECT_FALSE(reader.parse<wire::ForceSample>(*m).has_value())
          << "a ToolSample channel parsed as ForceSample";
      ++tools;
    } else if (m->channel_id == c.datagram) {
      const auto d = reader.parse<wire::Datagram>(*m);
      ASSERT_TRUE(d.has_value());
      EXPECT_EQ(d->header().sequence(), i);
      EXPECT_EQ(d->has_tool(), i % 2 == 0);
    }
    ++i;
  }
  EXPECT_EQ(i, kCount);
  EXPECT_EQ(tools, kCount / 3);
  EXPECT_TRUE(reader.complete());
  EXPECT_FALSE(reader.truncated());
  EXPECT_EQ(reader.truncation(), "");
  EXPECT_EQ(reader.valid_bytes(), fs::file_size(file));

  ASSERT_EQ(reader.schemas().size(), 3u);
  EXPECT_EQ(reader.schemas().at(1).name, "cohaptic.wire.ToolSample");
  EXPECT_EQ(reader.schemas().at(2).name, "cohaptic.wire.Datagram");
  EXPECT_EQ(reader.schemas().at(3).name, "cohaptic.wire.ForceSample");
  for (const auto& [id, schema] : reader.schemas()) {
    EXPECT_EQ(schema.id, id);
    EXPECT_EQ(schema.encoding, "protobuf");
  }
  EXPECT_EQ(reader.schemas().at(2).data, protobuf_schema_data(wire::Datagram::descriptor()));

  ASSERT_EQ(reader.channels().size(), 3u);
  const McapChannel& tool = reader.channels().at(c.tool);
  EXPECT_EQ(tool.topic, "/user0/tool");
  EXPECT_EQ(tool.schema_id, 1);
  EXPECT_EQ(tool.message_encoding, "protobuf");
  EXPECT_EQ(tool.metadata, kToolMetadata);
  EXPECT_EQ(reader.channels().at(c.datagram).topic, "/udp/received");
  EXPECT_TRUE(reader.channels().at(c.datagram).metadata.empty());
  EXPECT_EQ(reader.channels().at(c.force).schema_id, 3);

  ASSERT_TRUE(reader.statistics().has_value());
  const McapStatistics& s = *reader.statistics();
  EXPECT_EQ(s.message_count, kCount);
  EXPECT_EQ(s.schema_count, 3);
  EXPECT_EQ(s.channel_count, 3u);
  const Bytes b = read_bytes(file);
  const std::vector<RawRecord> records = walk(b);
  const auto chunks = std::count_if(records.begin(), records.end(),
                                    [](const RawRecord& r) { return r.opcode == 0x06; });
  EXPECT_GT(chunks, 50) << "4 kB chunks";
  EXPECT_EQ(s.chunk_count, static_cast<std::uint32_t>(chunks));
  EXPECT_EQ(s.message_start_time_ns, kEpochNs);
  EXPECT_EQ(s.message_end_time_ns, kEpochNs + std::uint64_t{kCount - 1} * 1'000'000);
  EXPECT_EQ(s.channel_message_counts, per_channel);
  EXPECT_FALSE(reader.next().has_value()) << "next() after the end stays at the end";

  // Every message in a chunk whose CRC matched, and the whole data section under Data End's.
  const McapCrcCoverage& crc = reader.crc_coverage();
  EXPECT_EQ(crc.checked_messages, kCount);
  EXPECT_EQ(crc.unchecked_messages, 0u);
  const auto data_end = std::find_if(records.begin(), records.end(),
                                     [](const RawRecord& r) { return r.opcode == 0x0F; });
  ASSERT_NE(data_end, records.end());
  EXPECT_EQ(crc.checked_through_offset, data_end->end());
  EXPECT_EQ(crc.checked_end_time_ns, s.message_end_time_ns);
}

TEST(McapRoundTrip, AnEmptySessionIsAValidFile) {
  const fs::path file = testing::scratch_directory("mcap-empty") / "empty.mcap";
  { McapWriter writer(file); }  // the destructor closes it
  McapReader reader(file);
  EXPECT_FALSE(reader.next().has_value());
  EXPECT_TRUE(reader.complete());
  ASSERT_TRUE(reader.statistics().has_value());
  EXPECT_EQ(reader.statistics()->message_count, 0u);
  EXPECT_EQ(reader.statistics()->message_start_time_ns, 0u);
}

// ---- the bytes on disk ----

TEST(McapLayout, ChunksIndexesSummaryAndFooterFollowTheSpec) {
  const fs::path file = testing::scratch_directory("mcap-layout") / "layout.mcap";
  const std::string schema_data = protobuf_schema_data(wire::ToolSample::descriptor());
  {
    McapWriter writer(file, McapWriterOptions{std::chrono::hours(1), std::size_t{1} << 20});
    EXPECT_EQ(writer.add_protobuf_schema(wire::ToolSample::descriptor()), 1);
    EXPECT_EQ(writer.add_channel(1, "/tool", "protobuf", {{"user", "0"}}), 1);
    writer.write(1, 7, 0x0102030405060708ull, 0x0102030405060700ull, Bytes{0xAA, 0xBB, 0xCC});
    writer.write(1, 8, 2000, 1900, Bytes{});
    writer.flush();  // the first chunk
    EXPECT_EQ(writer.add_channel(0, "/raw", "application/octet-stream"), 2);
    writer.write(2, 9, 3000, 3000, Bytes{0x01});
    writer.write(1, 10, 2500, 2500, Bytes{0x02, 0x03});
    EXPECT_EQ(writer.message_count(), 4u);
    writer.close();  // the second chunk, then the summary
    EXPECT_TRUE(writer.is_closed());
  }
  const Bytes b = read_bytes(file);
  ASSERT_GT(b.size(), 16u);
  EXPECT_EQ(text(b, 0, 8), kMagic);
  EXPECT_EQ(text(b, b.size() - 8, 8), kMagic);

  const std::vector<RawRecord> r = walk(b);
  // Header; Chunk, its Message Index; Chunk, its two Message Indexes (channels 1, 2); Data
  // End; summary: Schema, 2 Channels, Statistics, 2 Chunk Indexes; 4 Summary Offsets; Footer.
  std::vector<int> opcodes;
  for (const auto& record : r) opcodes.push_back(record.opcode);
  EXPECT_EQ(opcodes, (std::vector<int>{0x01, 0x06, 0x07, 0x06, 0x07, 0x07, 0x0F, 0x03, 0x04, 0x04,
                                       0x0B, 0x08, 0x08, 0x0E, 0x0E, 0x0E, 0x0E, 0x02}));
  ASSERT_EQ(r.size(), 18u);
  EXPECT_EQ(r.back().end() + 8, b.size()) << "the Footer is followed by the magic and nothing else";
  const auto bytes_of = [&](std::size_t begin, std::size_t end) {
    return Bytes(b.begin() + static_cast<long>(begin), b.begin() + static_cast<long>(end));
  };
  const auto record_bytes = [&](const RawRecord& record) {
    return bytes_of(record.offset, record.end());
  };

  // Header: profile "", library "cohaptic"; outside any chunk, as the first record must be.
  EXPECT_EQ(r[0].offset, 8u);
  EXPECT_EQ(r[0].length, 4u + 0 + 4 + 8);
  EXPECT_EQ(le32(b, r[0].content()), 0u);
  EXPECT_EQ(le32(b, r[0].content() + 4), 8u);
  EXPECT_EQ(text(b, r[0].content() + 8, 8), "cohaptic");

  // The first Chunk: message start and end time, uncompressed size, the CRC of its records,
  // compression "" (none), the records' u64 length, then the records.
  const RawChunk first = read_chunk(b, r[1]);
  EXPECT_EQ(first.message_start_time, 2000u);
  EXPECT_EQ(first.message_end_time, 0x0102030405060708ull);
  EXPECT_EQ(first.compression, "");
  EXPECT_EQ(first.records_begin, r[1].content() + 40);
  EXPECT_EQ(first.records_end, r[1].end()) << "the records fill the rest of the Chunk";
  EXPECT_EQ(first.uncompressed_size, first.records_end - first.records_begin);
  EXPECT_EQ(first.uncompressed_crc, reference_crc(b, first.records_begin, first.records_end));
  const std::vector<RawRecord> in_first =
      testing::records_between(b, first.records_begin, first.records_end);
  ASSERT_EQ(in_first.size(), 4u);
  EXPECT_EQ(in_first.back().end(), first.records_end);
  EXPECT_EQ(in_first[0].opcode, 0x03);
  EXPECT_EQ(in_first[1].opcode, 0x04);
  EXPECT_EQ(in_first[2].opcode, 0x05);
  EXPECT_EQ(in_first[3].opcode, 0x05);

  // Schema: id, name, encoding, u32-prefixed data.
  std::size_t at = in_first[0].content();
  EXPECT_EQ(le16(b, at), 1);
  const std::string name = "cohaptic.wire.ToolSample";
  EXPECT_EQ(le32(b, at + 2), name.size());
  EXPECT_EQ(text(b, at + 6, name.size()), name);
  at += 6 + name.size();
  EXPECT_EQ(le32(b, at), 8u);
  EXPECT_EQ(text(b, at + 4, 8), "protobuf");
  at += 12;
  EXPECT_EQ(le32(b, at), schema_data.size());
  EXPECT_EQ(text(b, at + 4, schema_data.size()), schema_data);
  EXPECT_EQ(in_first[0].length, 2 + 4 + name.size() + 4 + 8 + 4 + schema_data.size());

  // Channel: id, schema id, topic, message encoding, Map<string, string>.
  at = in_first[1].content();
  EXPECT_EQ(le16(b, at), 1);
  EXPECT_EQ(le16(b, at + 2), 1);
  EXPECT_EQ(le32(b, at + 4), 5u);
  EXPECT_EQ(text(b, at + 8, 5), "/tool");
  EXPECT_EQ(le32(b, at + 13), 8u);
  EXPECT_EQ(text(b, at + 17, 8), "protobuf");
  EXPECT_EQ(le32(b, at + 25), 4u + 4 + 4 + 1) << "map byte length";
  EXPECT_EQ(le32(b, at + 29), 4u);
  EXPECT_EQ(text(b, at + 33, 4), "user");
  EXPECT_EQ(le32(b, at + 37), 1u);
  EXPECT_EQ(text(b, at + 41, 1), "0");
  EXPECT_EQ(in_first[1].length, 42u);

  // Message: channel, sequence, log time, publish time, data; little-endian on disk.
  at = in_first[2].content();
  EXPECT_EQ(in_first[2].length, 22u + 3);
  EXPECT_EQ(le16(b, at), 1);
  EXPECT_EQ(le32(b, at + 2), 7u);
  EXPECT_EQ(bytes_of(at + 6, at + 14), (Bytes{0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01}));
  EXPECT_EQ(le64(b, at + 14), 0x0102030405060700ull);
  EXPECT_EQ(bytes_of(at + 22, in_first[2].end()), (Bytes{0xAA, 0xBB, 0xCC}));
  EXPECT_EQ(in_first[3].length, 22u);
  EXPECT_EQ(le32(b, in_first[3].content() + 2), 8u);

  // Message Index: channel, then (log time, offset from the start of the chunk's records)
  // for each of its messages in the chunk.
  const auto expect_index =
      [&](const RawRecord& index, std::uint16_t channel,
          const std::vector<std::pair<std::uint64_t, const RawRecord*>>& entries,
          const RawChunk& chunk) {
        EXPECT_EQ(le16(b, index.content()), channel);
        EXPECT_EQ(le32(b, index.content() + 2), entries.size() * 16);
        EXPECT_EQ(index.length, 2 + 4 + entries.size() * 16);
        for (std::size_t k = 0; k < entries.size(); ++k) {
          EXPECT_EQ(le64(b, index.content() + 6 + 16 * k), entries[k].first) << "entry " << k;
          EXPECT_EQ(le64(b, index.content() + 14 + 16 * k),
                    entries[k].second->offset - chunk.records_begin)
              << "entry " << k;
        }
      };
  expect_index(r[2], 1, {{0x0102030405060708ull, &in_first[2]}, {2000, &in_first[3]}}, first);

  // The second Chunk: the channel added after the first flush, then its messages.
  const RawChunk second = read_chunk(b, r[3]);
  EXPECT_EQ(r[3].offset, r[2].end());
  EXPECT_EQ(second.message_start_time, 2500u);
  EXPECT_EQ(second.message_end_time, 3000u);
  EXPECT_EQ(second.uncompressed_crc, reference_crc(b, second.records_begin, second.records_end));
  const std::vector<RawRecord> in_second =
      testing::records_between(b, second.records_begin, second.records_end);
  ASSERT_EQ(in_second.size(), 3u);
  EXPECT_EQ(in_second[0].opcode, 0x04);
  EXPECT_EQ(le16(b, in_second[0].content()), 2);
  EXPECT_EQ(le16(b, in_second[0].content() + 2), 0) << "no schema";
  EXPECT_EQ(le32(b, in_second[1].content() + 2), 9u);
  EXPECT_EQ(le32(b, in_second[2].content() + 2), 10u);
  expect_index(r[4], 1, {{2500, &in_second[2]}}, second);
  expect_index(r[5], 2, {{3000, &in_second[1]}}, second);

  // Data End: the CRC of every byte before it.
  EXPECT_EQ(r[6].length, 4u);
  EXPECT_EQ(le32(b, r[6].content()), reference_crc(b, 0, r[6].offset));

  // Summary: the Schema and Channel records again, byte for byte, then Statistics.
  EXPECT_EQ(record_bytes(r[7]), record_bytes(in_first[0]));
  EXPECT_EQ(record_bytes(r[8]), record_bytes(in_first[1]));
  EXPECT_EQ(record_bytes(r[9]), record_bytes(in_second[0]));
  at = r[10].content();
  EXPECT_EQ(le64(b, at), 4u) << "message_count";
  EXPECT_EQ(le16(b, at + 8), 1) << "schema_count";
  EXPECT_EQ(le32(b, at + 10), 2u) << "channel_count";
  EXPECT_EQ(le32(b, at + 14), 0u) << "attachment_count";
  EXPECT_EQ(le32(b, at + 18), 0u) << "metadata_count";
  EXPECT_EQ(le32(b, at + 22), 2u) << "chunk_count";
  EXPECT_EQ(le64(b, at + 26), 2000u) << "message_start_time";
  EXPECT_EQ(le64(b, at + 34), 0x0102030405060708ull) << "message_end_time";
  EXPECT_EQ(le32(b, at + 42), 20u) << "channel_message_counts byte length";
  EXPECT_EQ(le16(b, at + 46), 1);
  EXPECT_EQ(le64(b, at + 48), 3u);
  EXPECT_EQ(le16(b, at + 56), 2);
  EXPECT_EQ(le64(b, at + 58), 1u);
  EXPECT_EQ(r[10].length, 66u);

  // Chunk Index, one per chunk: its time range, where it is and how long, where each of its
  // Message Index records is and their length, compression and sizes.
  const auto expect_chunk_index =
      [&](const RawRecord& index, const RawRecord& chunk_record, const RawChunk& chunk,
          const std::vector<std::pair<std::uint16_t, const RawRecord*>>& indexes) {
        at = index.content();
        EXPECT_EQ(le64(b, at), chunk.message_start_time);
        EXPECT_EQ(le64(b, at + 8), chunk.message_end_time);
        EXPECT_EQ(le64(b, at + 16), chunk_record.offset) << "chunk_start_offset";
        EXPECT_EQ(le64(b, at + 24), chunk_record.end() - chunk_record.offset)
            << "chunk_length, prefix included";
        EXPECT_EQ(le32(b, at + 32), indexes.size() * 10) << "message_index_offsets byte length";
        at += 36;
        for (const auto& [channel, message_index] : indexes) {
          EXPECT_EQ(le16(b, at), channel);
          EXPECT_EQ(le64(b, at + 2), message_index->offset);
          at += 10;
        }
        EXPECT_EQ(le64(b, at), indexes.back().second->end() - chunk_record.end())
            << "message_index_length";
        EXPECT_EQ(le32(b, at + 8), 0u) << "compression \"\"";
        EXPECT_EQ(le64(b, at + 12), chunk.records_end - chunk.records_begin) << "compressed_size";
        EXPECT_EQ(le64(b, at + 20), chunk.uncompressed_size) << "uncompressed_size";
        EXPECT_EQ(at + 28, index.end());
      };
  expect_chunk_index(r[11], r[1], first, {{1, &r[2]}});
  expect_chunk_index(r[12], r[3], second, {{1, &r[4]}, {2, &r[5]}});

  // Summary Offsets: one per group, pointing at it.
  const std::vector<std::tuple<int, const RawRecord*, const RawRecord*>> groups = {
      {0x03, &r[7], &r[7]}, {0x04, &r[8], &r[9]}, {0x0B, &r[10], &r[10]}, {0x08, &r[11], &r[12]}};
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const auto& [op, group_first, group_last] = groups[g];
    const RawRecord& offset = r[13 + g];
    EXPECT_EQ(offset.length, 17u);
    EXPECT_EQ(b[offset.content()], op);
    EXPECT_EQ(le64(b, offset.content() + 1), group_first->offset);
    EXPECT_EQ(le64(b, offset.content() + 9), group_last->end() - group_first->offset);
  }

  // Footer: summary start, summary offset start, and the CRC from the summary through
  // the Footer's summary_offset_start field.
  const RawRecord& footer = r[17];
  EXPECT_EQ(footer.offset, b.size() - 8 - 29) << "the Footer is the last record";
  EXPECT_EQ(footer.length, 20u);
  EXPECT_EQ(le64(b, footer.content()), r[7].offset);
  EXPECT_EQ(r[7].offset, r[6].end()) << "the summary starts right after Data End";
  EXPECT_EQ(le64(b, footer.content() + 8), r[13].offset);
  EXPECT_EQ(le32(b, footer.content() + 16), reference_crc(b, r[7].offset, footer.content() + 16));
}

// ---- protobuf schemas ----

TEST(McapSchema, TheDescriptorSetDecodesARecordedMessageWithoutTheGeneratedClass) {
  EXPECT_EQ(schema_name(wire::ToolSample::descriptor()), "cohaptic.wire.ToolSample");
  const fs::path file = testing::scratch_directory("mcap-schema") / "schema.mcap";
  const Channels c = record_session(file, 30);

  McapReader reader(file);
  std::optional<McapMessage> recorded;
  while (auto m = reader.next()) {
    if (m->channel_id == c.datagram && m->sequence == 10) recorded = std::move(m);
  }
  ASSERT_TRUE(recorded.has_value());
  const McapSchema* schema = reader.schema_of(*recorded);
  ASSERT_NE(schema, nullptr);
  EXPECT_EQ(schema->name, "cohaptic.wire.Datagram");
  EXPECT_EQ(schema->encoding, "protobuf");

  google::protobuf::FileDescriptorSet set;
  ASSERT_TRUE(set.ParseFromString(schema->data));
  std::vector<std::string> names;
  for (const auto& f : set.file()) names.push_back(f.name());
  EXPECT_EQ(names, std::vector<std::string>{"cohaptic/messages.proto"});

  // A pool of its own, built from the recorded bytes only.
  google::protobuf::DescriptorPool pool;
  for (const auto& f : set.file()) ASSERT_NE(pool.BuildFile(f), nullptr) << f.name();
  const google::protobuf::Descriptor* type = pool.FindMessageTypeByName(schema->name);
  ASSERT_NE(type, nullptr);
  EXPECT_NE(type, wire::Datagram::descriptor()) << "not the generated class's descriptor";
  google::protobuf::DynamicMessageFactory factory(&pool);
  std::unique_ptr<google::protobuf::Message> message(factory.GetPrototype(type)->New());
  ASSERT_TRUE(
      message->ParseFromArray(recorded->data.data(), static_cast<int>(recorded->data.size())));

  const auto* reflection = message->GetReflection();
  const auto& header = reflection->GetMessage(*message, type->FindFieldByName("header"));
  EXPECT_EQ(header.GetReflection()->GetUInt64(header,
                                              header.GetDescriptor()->FindFieldByName("sequence")),
            10u);
  EXPECT_EQ(
      header.GetReflection()->GetUInt64(header, header.GetDescriptor()->FindFieldByName("session")),
      0x5e55'1000'0001u);
  const google::protobuf::FieldDescriptor* tool_field = type->FindFieldByName("tool");
  ASSERT_TRUE(reflection->HasField(*message, tool_field));
  const auto& tool = reflection->GetMessage(*message, tool_field);
  const auto& position =
      tool.GetReflection()->GetMessage(tool, tool.GetDescriptor()->FindFieldByName("position"));
  EXPECT_EQ(
      position.GetReflection()->GetDouble(position, position.GetDescriptor()->FindFieldByName("x")),
      tool_sample(10).position().x());
  EXPECT_EQ(
      position.GetReflection()->GetDouble(position, position.GetDescriptor()->FindFieldByName("z")),
      tool_sample(10).position().z());
  EXPECT_EQ(message->SerializeAsString(), datagram(10).SerializeAsString());
}

TEST(McapSchema, TheDescriptorSetHoldsEveryImportOnceBeforeItsImporters) {
  // google/protobuf/api.proto imports type.proto and source_context.proto; type.proto
  // imports any.proto and source_context.proto.
  google::protobuf::FileDescriptorSet set;
  ASSERT_TRUE(set.ParseFromString(protobuf_schema_data(google::protobuf::Api::descriptor())));
  std::vector<std::string> names;
  for (const auto& f : set.file()) names.push_back(f.name());
  EXPECT_EQ(
      std::set<std::string>(names.begin(), names.end()),
      (std::set<std::string>{"google/protobuf/api.proto", "google/protobuf/type.proto",
                             "google/protobuf/source_context.proto", "google/protobuf/any.proto"}));
  EXPECT_EQ(names.size(), 4u) << "each file once";
  EXPECT_EQ(names.back(), "google/protobuf/api.proto");
  google::protobuf::DescriptorPool
      pool;  // BuildFile fails on a file whose imports are not built yet
  for (const auto& f : set.file())
    ASSERT_NE(pool.BuildFile(f), nullptr) << f.name() << " before its imports";
  EXPECT_NE(pool.FindMessageTypeByName("google.protobuf.Api"), nullptr);
}

// ---- truncation ----

// Cuts `b`, a file of the messages `expected` in order of log time, at thousands of points
// (shortening one file): each cut yields exactly the messages whose top-level record (their
// Chunk, or themselves outside chunks) is complete before it; the readable prefix ends with
// the last complete record; and crc_coverage() counts them as checked when a Chunk's CRC
// covers them (or Data End's, once the cut leaves it), as unchecked otherwise.
void expect_every_cut_yields_the_messages_complete_before_it(
    const fs::path& dir, const Bytes& b, const std::vector<McapMessage>& expected) {
  const std::vector<RawRecord> records = walk(b);
  std::vector<std::size_t> readable_from;
  for (const testing::RawMessage& m : testing::messages_of(b))
    readable_from.push_back(m.readable_from);
  ASSERT_EQ(readable_from.size(), expected.size());
  std::vector<std::size_t> record_ends = {8};
  std::vector<std::size_t> chunk_ends = {0};
  for (const auto& r : records) {
    record_ends.push_back(r.end());
    if (r.opcode == 0x06) chunk_ends.push_back(r.end());
  }
  record_ends.push_back(b.size());
  const bool chunked = chunk_ends.size() > 1;
  const auto first_of = [&](int opcode) {
    return std::find_if(records.begin(), records.end(),
                        [&](const RawRecord& r) { return r.opcode == opcode; });
  };
  ASSERT_NE(first_of(0x0F), records.end());
  const RawRecord data_end = *first_of(0x0F);

  // Cut points: every byte of the first records and of the summary, footer and magic; the
  // edges of every 10th record (start, inside the prefix, just past it, last byte); and
  // every 37th byte elsewhere.
  std::set<std::size_t> cuts;
  for (std::size_t k = 0; k < 600 && k <= b.size(); ++k) cuts.insert(k);
  for (std::size_t k = readable_from.back() - 1; k <= data_end.end() + 200; ++k) cuts.insert(k);
  for (std::size_t k = first_of(0x0B)->offset; k <= b.size(); ++k) cuts.insert(k);
  for (std::size_t i = 0; i < records.size(); i += (i < 20 || i + 20 > records.size()) ? 1 : 10) {
    for (std::size_t d : {0, 1, 8, 9, 10}) cuts.insert(records[i].offset + d);
    cuts.insert(records[i].end() - 1);
  }
  for (std::size_t k = 0; k < b.size(); k += 37) cuts.insert(k);

  const fs::path cut_file = dir / "cut.mcap";
  write_bytes(cut_file, b);
  std::size_t checked = 0;
  for (auto it = cuts.rbegin(); it != cuts.rend(); ++it) {  // from the longest, shortening one file
    const std::size_t cut = *it;
    if (cut > b.size()) continue;
    fs::resize_file(cut_file, cut);
    SCOPED_TRACE("cut at byte " + std::to_string(cut) + " of " + std::to_string(b.size()));
    const std::size_t complete_messages = static_cast<std::size_t>(
        std::upper_bound(readable_from.begin(), readable_from.end(), cut) - readable_from.begin());
    const std::size_t valid =
        cut < 8 ? 0 : *(std::upper_bound(record_ends.begin(), record_ends.end(), cut) - 1);

    McapReader reader(cut_file);
    std::vector<McapMessage> got = read_all(reader);
    ASSERT_EQ(got.size(), complete_messages);
    for (std::size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got[i], expected[i]) << "message " << i;
    ASSERT_EQ(reader.truncated(), cut < b.size());
    ASSERT_EQ(reader.complete(), cut == b.size());
    ASSERT_EQ(reader.valid_bytes(), valid);
    ASSERT_EQ(reader.truncation().empty(), cut == b.size()) << reader.truncation();
    if (cut >= 8 + 9 + 16) {
      EXPECT_EQ(reader.library(), "cohaptic");
    }

    McapCrcCoverage coverage;
    if (cut >= data_end.end()) {
      coverage.checked_messages = expected.size();
      coverage.checked_through_offset = data_end.end();
    } else if (chunked) {
      coverage.checked_messages = complete_messages;
      coverage.checked_through_offset =
          *(std::upper_bound(chunk_ends.begin(), chunk_ends.end(), cut) - 1);
    } else {
      coverage.unchecked_messages = complete_messages;
    }
    if (coverage.checked_messages > 0)
      coverage.checked_end_time_ns = expected[coverage.checked_messages - 1].log_time_ns;
    ASSERT_EQ(reader.crc_coverage(), coverage);
    ++checked;
  }
  EXPECT_GT(checked, 3000u);
  std::printf("checked %zu cut points of a %zu-byte file\n", checked, b.size());
}

std::vector<McapMessage> expected_messages(const Channels& c, std::uint32_t count) {
  std::vector<McapMessage> expected;
  for (std::uint32_t i = 0; i < count; ++i) expected.push_back(expected_message(c, i));
  return expected;
}

TEST(McapTruncation, EveryCutOfAChunkedFileYieldsExactlyTheMessagesOfItsCompleteChunks) {
  const fs::path dir = testing::scratch_directory("mcap-truncation");
  const fs::path file = dir / "full.mcap";
  constexpr std::uint32_t kCount = 1000;
  const Channels c = record_session(file, kCount);
  const Bytes b = read_bytes(file);
  expect_every_cut_yields_the_messages_complete_before_it(dir, b, expected_messages(c, kCount));

  // The descriptions say where the file ends: inside the fifth chunk, or right after it.
  const std::vector<RawRecord> records = walk(b);
  std::vector<RawRecord> chunks;
  std::copy_if(records.begin(), records.end(), std::back_inserter(chunks),
               [](const RawRecord& r) { return r.opcode == 0x06; });
  ASSERT_GT(chunks.size(), 10u);
  const fs::path cut_file = dir / "cut.mcap";
  const auto cut_copy = [&](std::size_t n) {
    write_bytes(cut_file, Bytes(b.begin(), b.begin() + static_cast<long>(n)));
  };
  const std::size_t in_first_four =
      testing::messages_of(Bytes(b.begin(), b.begin() + static_cast<long>(chunks[4].offset)))
          .size();
  cut_copy(chunks[4].offset + 9 + 100);
  McapReader mid(cut_file);
  EXPECT_EQ(read_all(mid).size(), in_first_four);
  EXPECT_EQ(mid.truncation(),
            "file ends 100 bytes into the content of a " + std::to_string(chunks[4].length) +
                "-byte Chunk record at offset " + std::to_string(chunks[4].offset));
  cut_copy(chunks[4].end());
  McapReader boundary(cut_file);
  EXPECT_GT(read_all(boundary).size(), in_first_four);
  EXPECT_EQ(boundary.truncation(), "file ends after the complete record ending at offset " +
                                       std::to_string(chunks[4].end()) + ", without a Footer");
}

// A file without chunks (a recording written unchunked) reads record by record; no CRC
// covers its messages until Data End.
TEST(McapTruncation, EveryCutOfAnUnchunkedFileYieldsExactlyTheMessagesCompleteBeforeIt) {
  const fs::path dir = testing::scratch_directory("mcap-truncation-unchunked");
  constexpr std::uint32_t kCount = 1000;
  const Channels c = record_session(dir / "chunked.mcap", kCount);
  const Bytes b = testing::unchunked(read_bytes(dir / "chunked.mcap"));
  const std::vector<RawRecord> records = walk(b);
  ASSERT_TRUE(std::none_of(records.begin(), records.end(), [](const RawRecord& r) {
    return r.opcode == 0x06 || r.opcode == 0x07;
  }));
  expect_every_cut_yields_the_messages_complete_before_it(dir, b, expected_messages(c, kCount));

  const std::vector<testing::RawMessage> messages = testing::messages_of(b);
  const fs::path cut_file = dir / "cut.mcap";
  const auto cut_copy = [&](std::size_t n) {
    write_bytes(cut_file, Bytes(b.begin(), b.begin() + static_cast<long>(n)));
  };
  cut_copy(messages[499].record.end() + 12);
  McapReader mid(cut_file);
  EXPECT_EQ(read_all(mid).size(), 500u);
  EXPECT_EQ(mid.truncation(), "file ends 3 bytes into the content of a " +
                                  std::to_string(messages[500].record.length) +
                                  "-byte Message record at offset " +
                                  std::to_string(messages[499].record.end()));
  cut_copy(messages[499].record.end());
  McapReader boundary(cut_file);
  EXPECT_EQ(read_all(boundary).size(), 500u);
  EXPECT_EQ(boundary.truncation(), "file ends after the complete record ending at offset " +
                                       std::to_string(messages[499].record.end()) +
                                       ", without a Footer");
}

// ---- a writer that dies ----

void expect_crash_leaves_flushed_messages(bool kill) {
  const fs::path file =
      testing::scratch_directory(kill ? "mcap-killed" : "mcap-exited") / "crashed.mcap";
  constexpr std::uint32_t kFlushed = 500;
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0) << std::strerror(errno);
  if (pid == 0) {  // the child: record, flush, write some more, and die without closing
    int code = 0;
    try {
      McapWriter writer(file, McapWriterOptions{std::chrono::hours(1), std::size_t{1} << 30});
      const Channels c = open_channels(writer);
      write_messages(writer, c, 0, kFlushed);
      writer.flush();
      write_messages(writer, c, kFlushed, 20);  // buffered only: lost with the process
      if (kill) ::raise(SIGKILL);
      ::_exit(0);
    } catch (...) {
      code = 3;
    }
    ::_exit(code);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  if (kill) {
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "status " << status;
  } else {
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
  }

  McapReader reader(file);
  Channels c;
  c.tool = 1;
  c.datagram = 2;
  c.force = 3;
  const std::vector<McapMessage> got = read_all(reader);
  ASSERT_EQ(got.size(), kFlushed);
  for (std::uint32_t i = 0; i < kFlushed; ++i)
    ASSERT_EQ(got[i], expected_message(c, i)) << "message " << i;
  EXPECT_EQ(reader.channels().size(), 3u);
  EXPECT_EQ(reader.schemas().size(), 3u);
  EXPECT_TRUE(reader.truncated());
  EXPECT_FALSE(reader.complete());
  EXPECT_EQ(reader.valid_bytes(), fs::file_size(file)) << "flushed records are whole";
  EXPECT_EQ(reader.crc_coverage().checked_messages, kFlushed)
      << "each flush left a chunk with its CRC";
  EXPECT_EQ(reader.crc_coverage().unchecked_messages, 0u);
}

TEST(McapCrash, AWriterKilledMidSessionLeavesEveryFlushedMessage) {
  expect_crash_leaves_flushed_messages(true);
}

TEST(McapCrash, AWriterExitingWithoutClosingLeavesEveryFlushedMessage) {
  expect_crash_leaves_flushed_messages(false);
}

// ---- flushing ----

TEST(McapWriter, FlushesWhenTheBufferFillsWhenTimeIsUpAndOnRequest) {
  const fs::path dir = testing::scratch_directory("mcap-flush");
  const auto on_disk = [](const fs::path& p) {
    return static_cast<std::uint64_t>(fs::file_size(p));
  };
  {
    const fs::path file = dir / "by-bytes.mcap";
    McapWriter writer(file, McapWriterOptions{std::chrono::hours(1), 1000});
    EXPECT_EQ(on_disk(file), writer.size()) << "the constructor flushes the Header";
    const Channels c = open_channels(writer);
    writer.flush();
    const std::uint64_t flushed = writer.size();
    std::uint64_t buffered = 0;
    std::uint32_t i = 0;
    while (on_disk(file) == flushed) {
      ASSERT_LT(buffered, 1000u) << "not flushed although 1000 bytes were buffered";
      write_messages(writer, c, i++, 1);
      buffered = writer.size() - flushed;
    }
    EXPECT_GE(buffered, 1000u);
    EXPECT_EQ(on_disk(file), writer.size());
    write_messages(writer, c, i++, 1);
    EXPECT_LT(on_disk(file), writer.size());
    writer.flush();
    EXPECT_EQ(on_disk(file), writer.size());
  }
  {
    const fs::path file = dir / "by-time.mcap";
    constexpr auto kInterval = 200ms;
    McapWriter writer(file, McapWriterOptions{kInterval, std::size_t{1} << 30});
    const Channels c = open_channels(writer);
    writer.flush();
    const auto flushed_at = std::chrono::steady_clock::now();
    write_messages(writer, c, 0, 1);
    if (std::chrono::steady_clock::now() - flushed_at < kInterval) {
      EXPECT_LT(on_disk(file), writer.size()) << "buffered before the interval is up";
    }
    std::this_thread::sleep_for(kInterval + 20ms);  // stimulus: the flush interval passing
    write_messages(writer, c, 1, 1);
    EXPECT_EQ(on_disk(file), writer.size()) << "a write after the interval flushes";
    write_messages(writer, c, 2, 1);
    std::this_thread::sleep_for(kInterval + 20ms);  // stimulus: the flush interval passing
    writer.flush_if_due();
    EXPECT_EQ(on_disk(file), writer.size()) << "flush_if_due after the interval flushes";
    writer.close();
    writer.close();  // a second close does nothing
    writer.flush();  // nor does a flush after it
    expect_error([&] { write_messages(writer, c, 3, 1); }, {"already closed"});
  }
}

// ---- errors ----

TEST(McapWriter, AFullDeviceThrowsWithTheReason) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this machine";
  expect_error([] { McapWriter writer("/dev/full"); }, {"/dev/full", std::strerror(ENOSPC)});
  expect_error([] { McapWriter writer("/nonexistent-dir/x.mcap"); },
               {"/nonexistent-dir/x.mcap", std::strerror(ENOENT)});
}

TEST(McapWriter, AWriteErrorMidSessionThrowsAndTheFileStaysReadable) {
  // A child whose file size limit stands in for a disk filling up mid-session.
  const fs::path file = testing::scratch_directory("mcap-write-error") / "limited.mcap";
  constexpr rlim_t kLimit = 64 * 1024;
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::close(pipe_fds[0]);
    ::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{kLimit, kLimit};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    std::string report;
    int code = 10;
    try {
      McapWriter writer(file, McapWriterOptions{std::chrono::hours(1), 4096});
      const Channels c = open_channels(writer);
      try {
        write_messages(writer, c, 0, 100000);
        code = 11;  // the limit never bit
      } catch (const Error& e) {
        report = std::string(e.what()) + "\n";
        code = 0;
      }
      try {
        write_messages(writer, c, 0, 1);
        code = 12;  // usable after the error
      } catch (const Error& e) {
        report += std::string(e.what()) + "\n";
      }
    } catch (...) {
      code = 13;
    }
    const ssize_t written = ::write(pipe_fds[1], report.data(), report.size());
    ::_exit(written == static_cast<ssize_t>(report.size()) ? code : 14);
  }
  ::close(pipe_fds[1]);
  std::string report;
  char buffer[4096];
  for (ssize_t n; (n = ::read(pipe_fds[0], buffer, sizeof buffer)) > 0;)
    report.append(buffer, static_cast<std::size_t>(n));
  ::close(pipe_fds[0]);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << "status " << status;
  ASSERT_EQ(WEXITSTATUS(status), 0) << report;

  const std::string first = report.substr(0, report.find('\n'));
  const std::string second = report.substr(report.find('\n') + 1);
  EXPECT_NE(first.find(file.string()), std::string::npos) << first;
  EXPECT_NE(first.find(std::strerror(EFBIG)), std::string::npos) << first;
  EXPECT_NE(second.find("unusable after an earlier error"), std::string::npos) << second;

  EXPECT_LE(fs::file_size(file), kLimit);
  McapReader reader(file);
  const std::vector<McapMessage> got = read_all(reader);
  EXPECT_TRUE(reader.truncated());
  // Every message of the chunks written whole before the limit bit (the schemas take 20 kB).
  EXPECT_EQ(got.size(), testing::messages_of(read_bytes(file)).size());
  EXPECT_GT(got.size(), 300u);
  EXPECT_EQ(reader.crc_coverage().checked_messages, got.size());
  Channels c;
  c.tool = 1;
  c.datagram = 2;
  c.force = 3;
  for (std::uint32_t i = 0; i < got.size(); ++i)
    ASSERT_EQ(got[i], expected_message(c, i)) << "message " << i;
}

TEST(McapWriter, WrongIdsThrowWithoutSpoilingTheRecording) {
  const fs::path file = testing::scratch_directory("mcap-ids") / "ids.mcap";
  McapWriter writer(file);
  expect_error([&] { writer.add_channel(1, "/nothing"); }, {"unknown schema 1"});
  const std::uint16_t raw = writer.add_channel(0, "/raw", "application/octet-stream");
  expect_error([&] { writer.write(2, 0, 0, 0, Bytes{1}); }, {"unknown channel 2"});
  expect_error([&] { writer.write(0, 0, 0, 0, Bytes{1}); }, {"unknown channel 0"});
  writer.write(raw, 1, 5, 5, Bytes{1, 2});
  writer.close();
  McapReader reader(file);
  const std::vector<McapMessage> got = read_all(reader);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].data, (Bytes{1, 2}));
  EXPECT_EQ(reader.schema_of(got[0]), nullptr);
  EXPECT_FALSE(reader.parse<wire::ToolSample>(got[0]).has_value());
  EXPECT_TRUE(reader.complete());
}

TEST(McapReader, RejectsFilesThatAreNotMcap) {
  const fs::path dir = testing::scratch_directory("mcap-not");
  const fs::path text_file = dir / "notes.txt";
  write_bytes(text_file, Bytes{'h', 'e', 'l', 'l', 'o', ',', ' ', 'w', 'o', 'r', 'l', 'd', '\n'});
  expect_error([&] { McapReader reader(text_file); }, {text_file.string(), "not an MCAP file"});
  const fs::path short_file = dir / "short.bin";
  write_bytes(short_file, Bytes{'#', '!'});
  expect_error([&] { McapReader reader(short_file); }, {short_file.string(), "not an MCAP file"});
  const fs::path v1 = dir / "v1.mcap";
  write_bytes(v1, Builder{}.u8(0x89).u8('M').u8('C').u8('A').u8('P').u8('1').u8('\r').u8('\n').out);
  expect_error([&] { McapReader reader(v1); }, {v1.string(), "unsupported MCAP major version '1'"});
  expect_error([&] { McapReader reader(dir / "missing.mcap"); },
               {(dir / "missing.mcap").string(), std::strerror(ENOENT)});
  expect_error([&] { McapReader reader(dir); }, {dir.string()});

  // An empty file, or a cut inside the magic, is a truncated recording, not a foreign file.
  const fs::path empty = dir / "empty.mcap";
  write_bytes(empty, Bytes{});
  McapReader reader(empty);
  EXPECT_FALSE(reader.next().has_value());
  EXPECT_TRUE(reader.truncated());
}

Bytes header_content() { return Builder{}.str("").str("hand-made").out; }
Bytes schema_content(std::uint16_t id) {
  return Builder{}.uint(id, 2).str("raw").str("").str("").out;
}
Bytes channel_content(std::uint16_t id, std::uint16_t schema) {
  return Builder{}.uint(id, 2).uint(schema, 2).str("/t").str("raw").uint(0, 4).out;
}
Bytes message_content(std::uint16_t channel, std::uint32_t sequence, const std::string& data) {
  Builder b;
  b.uint(channel, 2).uint(sequence, 4).uint(100 + sequence, 8).uint(90 + sequence, 8);
  b.out.insert(b.out.end(), data.begin(), data.end());
  return b.out;
}
Bytes footer_content() { return Builder{}.uint(0, 8).uint(0, 8).uint(0, 4).out; }

// A Chunk's content around `records`: uncompressed unless `compression` says otherwise,
// with their CRC unless `crc` is given (0: none computed).
Bytes chunk_content(const Bytes& records, std::optional<std::uint32_t> crc = std::nullopt,
                    const std::string& compression = "",
                    std::optional<std::uint64_t> uncompressed_size = std::nullopt) {
  Builder chunk;
  chunk.uint(100, 8).uint(101, 8).uint(uncompressed_size.value_or(records.size()), 8);
  chunk.uint(crc.value_or(reference_crc(records, 0, records.size())), 4)
      .str(compression)
      .uint(records.size(), 8);
  chunk.out.insert(chunk.out.end(), records.begin(), records.end());
  return chunk.out;
}

TEST(McapReader, ReadsChunksCheckingTheirCrcs) {
  const fs::path file = testing::scratch_directory("mcap-chunks") / "chunks.mcap";
  Builder b;
  b.magic().record(0x01, header_content());
  Builder first;
  first.record(0x03, schema_content(1)).record(0x04, channel_content(1, 1));
  first.record(0x05, message_content(1, 1, "first"))
      .record(0x80, Bytes{7, 7});  // a record of a later spec: skipped
  first.record(0x05, message_content(1, 2, "second"));
  b.record(0x06, chunk_content(first.out));
  b.record(
      0x07,
      Builder{}.uint(1, 2).uint(0, 4).out);  // a Message Index: of no use when reading in order
  const std::size_t unchecked_chunk = b.out.size();
  b.record(0x06, chunk_content(Builder{}.record(0x05, message_content(1, 3, "third")).out, 0));
  b.record(0x05, message_content(1, 4, "fourth"));  // outside any chunk
  b.record(0x0F, Builder{}.uint(0, 4).out).record(0x02, footer_content()).magic();
  write_bytes(file, b.out);

  McapReader reader(file);
  const std::vector<McapMessage> got = read_all(reader);
  ASSERT_EQ(got.size(), 4u);
  EXPECT_EQ(std::string(got[0].data.begin(), got[0].data.end()), "first");
  EXPECT_EQ(got[1].sequence, 2u);
  EXPECT_EQ(std::string(got[2].data.begin(), got[2].data.end()), "third");
  EXPECT_EQ(got[3].log_time_ns, 104u);
  EXPECT_EQ(reader.channels().size(), 1u);
  EXPECT_TRUE(reader.complete());
  // The first chunk's CRC matched; the second has none (0), the last message is outside
  // chunks, and Data End carries no CRC either.
  McapCrcCoverage coverage;
  coverage.checked_messages = 2;
  coverage.unchecked_messages = 2;
  coverage.checked_through_offset = 34 + 9 + chunk_content(first.out).size();
  coverage.checked_end_time_ns = 102;
  EXPECT_EQ(reader.crc_coverage(), coverage);
  EXPECT_LT(coverage.checked_through_offset, unchecked_chunk);
}

TEST(McapReader, RejectsDamagedAndMalformedChunksNamingThem) {
  const fs::path dir = testing::scratch_directory("mcap-bad-chunks");
  const Bytes records = Builder{}
                            .record(0x03, schema_content(1))
                            .record(0x04, channel_content(1, 1))
                            .record(0x05, message_content(1, 1, "x"))
                            .out;
  const auto expect_rejected = [&](const std::string& name, const Bytes& content,
                                   const std::vector<std::string>& parts) {
    const fs::path file = dir / name;
    Builder b;
    b.magic().record(0x01, header_content()).record(0x06, content);
    b.record(0x0F, Builder{}.uint(0, 4).out).record(0x02, footer_content()).magic();
    write_bytes(file, b.out);
    McapReader reader(file);
    std::vector<std::string> all = parts;
    all.push_back(file.string());
    expect_error([&] { reader.next(); }, all);
    expect_error([&] { reader.next(); }, all);  // and it stays failed
  };
  // The chunk at offset 34 (magic 8, Header 9 + 17): a wrong CRC yields none of its messages.
  const std::uint32_t crc = reference_crc(records, 0, records.size());
  expect_rejected("crc.mcap", chunk_content(records, crc ^ 0x10u),
                  {"Chunk record at offset 34", "messages logged from 100 to 101 ns",
                   fmt::format("recorded as {:08x} but computes to {:08x}", crc ^ 0x10u, crc)});
  expect_rejected("zstd.mcap", chunk_content(records, std::nullopt, "zstd"),
                  {"Chunk record at offset 34", "compressed ('zstd')"});
  expect_rejected(
      "size.mcap", chunk_content(records, std::nullopt, "", records.size() + 1),
      {"Chunk record at offset 34", fmt::format("uncompressed_size is {}", records.size() + 1)});
  Bytes overrun = records;
  overrun.resize(overrun.size() - 1);  // the message's content runs past the chunk's records
  expect_rejected("overrun.mcap", chunk_content(overrun),
                  {"Message record at offset", "inside the Chunk at offset 34",
                   "run past the end of the chunk's records"});
  expect_rejected("header.mcap", chunk_content(Builder{}.record(0x01, header_content()).out),
                  {"Header record at offset 83 inside the Chunk at offset 34",
                   "only Schema, Channel and Message"});
  expect_rejected("orphan.mcap",
                  chunk_content(Builder{}.record(0x05, message_content(1, 1, "x")).out),
                  {"Message record at offset 83 inside the Chunk at offset 34",
                   "which no earlier Channel record defines"});
}

TEST(McapReader, SkipsRecordTypesItDoesNotKnowAndFieldsAddedLater) {
  const fs::path file = testing::scratch_directory("mcap-unknown") / "unknown.mcap";
  Builder b;
  b.magic().record(0x01, header_content());
  Bytes extended_schema = schema_content(1);
  extended_schema.push_back(0x42);  // "records may be extended by adding new fields at the end"
  b.record(0x03, extended_schema).record(0x04, channel_content(1, 1));
  b.record(0x80, Bytes{1, 2, 3, 4, 5});  // an application extension
  b.record(0x05, message_content(1, 1, "first"));
  b.record(0x09, Bytes(40, 0x11));                       // an attachment: known, of no use here
  b.record(0x0C, Builder{}.str("info").uint(0, 4).out);  // metadata
  b.record(0x7E, Bytes{});                               // a future MCAP record, empty
  b.record(0x05, message_content(1, 2, "second"));
  b.record(0x0F, Builder{}.uint(0, 4).out).record(0x02, footer_content()).magic();
  write_bytes(file, b.out);

  McapReader reader(file);
  EXPECT_EQ(reader.library(), "hand-made");
  const std::vector<McapMessage> got = read_all(reader);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(std::string(got[0].data.begin(), got[0].data.end()), "first");
  EXPECT_EQ(got[1].sequence, 2u);
  EXPECT_EQ(got[1].log_time_ns, 102u);
  EXPECT_EQ(got[1].publish_time_ns, 92u);
  EXPECT_TRUE(reader.complete());
  EXPECT_FALSE(reader.truncated());
}

TEST(McapReader, RejectsMalformedAndCorruptFiles) {
  const fs::path dir = testing::scratch_directory("mcap-malformed");
  const auto expect_rejected = [&](const std::string& name, const Bytes& bytes,
                                   const std::string& part) {
    const fs::path file = dir / name;
    write_bytes(file, bytes);
    expect_error(
        [&] {
          McapReader reader(file);
          read_all(reader);
        },
        {file.string(), part});
  };
  Builder start;
  start.magic()
      .record(0x01, header_content())
      .record(0x03, schema_content(1))
      .record(0x04, channel_content(1, 1));

  Builder orphan = start;
  orphan.record(0x05, message_content(2, 1, "x"));
  expect_rejected("orphan.mcap", orphan.out,
                  "message on channel 2, which no earlier Channel record defines");

  Builder short_record = start;
  short_record.record(0x05, Bytes{1, 0, 0});
  expect_rejected("short.mcap", short_record.out, "Message record at offset");

  Builder redefined = start;
  redefined.record(0x04, Builder{}.uint(1, 2).uint(1, 2).str("/other").str("raw").uint(0, 4).out);
  expect_rejected("redefined.mcap", redefined.out, "channel 1 ('/other') differs");

  Builder no_header;
  no_header.magic().record(0x03, schema_content(1));
  expect_rejected("no-header.mcap", no_header.out, "expected a Header record");

  // One flipped bit inside a message's data: the structure holds, its chunk's CRC does not,
  // and none of that chunk's messages is returned.
  const fs::path good = dir / "good.mcap";
  record_session(good, 100);
  const Bytes intact = read_bytes(good);
  const std::vector<RawRecord> records = walk(intact);
  const std::vector<testing::RawMessage> messages = testing::messages_of(intact);
  const auto first_chunk = std::find_if(records.begin(), records.end(), [&](const RawRecord& r) {
    return r.end() == messages.front().readable_from;
  });
  ASSERT_NE(first_chunk, records.end());
  ASSERT_EQ(first_chunk->opcode, 0x06) << "the first message is in a chunk";
  Bytes corrupt = intact;
  corrupt[messages[5].record.content() + 23] ^= 0x04;
  ASSERT_EQ(messages[5].readable_from, first_chunk->end());
  expect_rejected("corrupt.mcap", corrupt,
                  "Chunk record at offset " + std::to_string(first_chunk->offset));
  {
    McapReader reader(dir / "corrupt.mcap");
    EXPECT_THROW(reader.next(), Error) << "the first message comes from the damaged chunk";
  }
  // A Message Index lies outside chunks: the data-section CRC covers it.
  const RawRecord& index = *(first_chunk + 1);
  ASSERT_EQ(index.opcode, 0x07);
  Bytes corrupt_index = intact;
  corrupt_index[index.content() + 10] ^= 0x01;
  expect_rejected("corrupt-index.mcap", corrupt_index, "data section CRC-32");
  Bytes corrupt_summary = intact;
  corrupt_summary[corrupt_summary.size() - 8 - 29 - 40] ^=
      0x01;  // a group_start in the Summary Offsets
  expect_rejected("corrupt-summary.mcap", corrupt_summary, "summary CRC-32");
}

// ---- the official reader ----

struct NodeRun {
  int status = -1;
  std::string output;
  std::string errors;
};

NodeRun run_mcap_check(const fs::path& file, const fs::path& errors) {
  const std::string command = "node '" + testing::source_path("tests/support/mcap_check.mjs") +
                              "' '" + file.string() + "' 2>'" + errors.string() + "'";
  NodeRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;)
    run.output.append(buffer, n);
  const int status = ::pclose(pipe);
  run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(errors);
  run.errors.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return run;
}

TEST(McapWriter, TheOfficialReaderReadsOurFiles) {
  if (std::system("node --version > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "node is not installed; this check needs node (v18 or later) and @mcap/core: "
                    "install Debian's nodejs and npm, then npm ci --prefix deploy/node "
                    "(deploy/install-deps.sh does both)";
  }
  if (!fs::exists(testing::source_path("deploy/node/node_modules/@mcap/core/package.json"))) {
    GTEST_SKIP() << "@mcap/core is not installed; from the source tree run: npm ci --prefix "
                    "deploy/node (deploy/install-deps.sh does)";
  }
  const fs::path dir = testing::scratch_directory("mcap-official");
  constexpr std::uint32_t kCount = 2400;
  const fs::path full = dir / "session.mcap";
  record_session(full, kCount);
  const std::vector<std::string> topics = {"/udp/received", "/user0/force", "/user0/tool"};
  const std::vector<std::string> schemas = {"cohaptic.wire.Datagram", "cohaptic.wire.ForceSample",
                                            "cohaptic.wire.ToolSample"};

  const auto check = [&](const fs::path& file) {
    const NodeRun run = run_mcap_check(file, dir / (file.filename().string() + ".stderr"));
    EXPECT_EQ(run.status, 0) << run.output << run.errors;
    nlohmann::json json;
    try {
      json = nlohmann::json::parse(run.output);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "mcap_check.mjs printed no JSON (" << e.what() << "): " << run.output
                    << run.errors;
    }
    return json;
  };

  {  // complete: the indexed reader opens it, the stream reader reads every message
    nlohmann::json j = check(full);
    ASSERT_FALSE(j.is_null());
    EXPECT_EQ(j["complete"], true) << j.dump();
    EXPECT_TRUE(j["indexError"].is_null()) << j.dump();
    EXPECT_EQ(j["messageCount"], kCount);
    EXPECT_EQ(j["channels"].get<std::vector<std::string>>(), topics);
    EXPECT_EQ(j["schemas"].get<std::vector<std::string>>(), schemas);
    EXPECT_EQ(j["library"], "cohaptic");
    nlohmann::json& indexed = j["indexed"];
    EXPECT_EQ(indexed["channels"].get<std::vector<std::string>>(), topics);
    EXPECT_EQ(indexed["schemas"].get<std::vector<std::string>>(), schemas);
    const std::vector<RawRecord> records = walk(read_bytes(full));
    const auto chunks = std::count_if(records.begin(), records.end(),
                                      [](const RawRecord& r) { return r.opcode == 0x06; });
    EXPECT_GT(chunks, 10);
    EXPECT_EQ(indexed["chunkCount"], chunks);
    EXPECT_EQ(indexed["summaryOffsetOpcodes"].get<std::vector<int>>(),
              (std::vector<int>{0x03, 0x04, 0x08, 0x0B}));
    EXPECT_EQ(indexed["statistics"]["messageCount"], kCount);
    EXPECT_EQ(indexed["statistics"]["channelCount"], 3);
    EXPECT_EQ(indexed["statistics"]["messageStartTime"], std::to_string(kEpochNs));
    // The indexed reader finds every message through the Chunk Index and Message Index records.
    EXPECT_EQ(indexed["messageCount"], kCount);
    for (const auto& topic : topics) {
      EXPECT_EQ(indexed["statistics"]["channelMessageCounts"][topic], kCount / 3) << topic;
      EXPECT_EQ(indexed["channelMessageCounts"][topic], kCount / 3) << topic;
      EXPECT_EQ(j["channelMessageCounts"][topic], kCount / 3) << topic;
    }
    // Recomputed with Node's zlib when it has crc32 (Node 20.15 and later).
    EXPECT_NE(indexed["dataSectionCrcOk"], false) << j.dump();
  }

  const Bytes b = read_bytes(full);
  const std::vector<testing::RawMessage> messages = testing::messages_of(b);
  const auto official_and_ours_agree_on_a_cut = [&](std::size_t cut, const std::string& name) {
    SCOPED_TRACE(name + " at byte " + std::to_string(cut));
    const fs::path file = dir / name;
    write_bytes(file, Bytes(b.begin(), b.begin() + static_cast<long>(cut)));
    McapReader reader(file);
    const std::size_t ours = read_all(reader).size();
    EXPECT_TRUE(reader.truncated());
    nlohmann::json j = check(file);
    if (j.is_null()) return ours;
    EXPECT_EQ(j["complete"], false) << j.dump();
    EXPECT_FALSE(j["indexError"].is_null())
        << "the indexed reader should refuse a file without a footer";
    EXPECT_EQ(j["messageCount"], ours) << j.dump();
    EXPECT_EQ(j["channels"].get<std::vector<std::string>>(), topics);
    return ours;
  };
  const auto readable_at = [&](std::size_t cut) {
    return static_cast<std::size_t>(
        std::count_if(messages.begin(), messages.end(),
                      [&](const testing::RawMessage& m) { return m.readable_from <= cut; }));
  };
  // Inside the 1501st message, so inside its chunk: that chunk is lost whole.
  const std::size_t inside = messages[1500].record.offset + 20;
  EXPECT_LT(readable_at(inside), 1500u);
  EXPECT_EQ(official_and_ours_agree_on_a_cut(inside, "cut-inside.mcap"), readable_at(inside));
  // Right after the chunk of the 1000th message, as a crashed writer leaves it.
  const std::size_t boundary = messages[999].readable_from;
  EXPECT_GE(readable_at(boundary), 1000u);
  EXPECT_EQ(official_and_ours_agree_on_a_cut(boundary, "cut-boundary.mcap"), readable_at(boundary));

  {  // that cut with a byte flipped in its last complete chunk: both readers check the chunk's CRC
    const fs::path file = dir / "cut-flipped.mcap";
    Bytes cut(b.begin(), b.begin() + static_cast<long>(boundary));
    cut[messages[999].record.content() + 22] ^= 0x20;
    write_bytes(file, cut);
    McapReader reader(file);
    EXPECT_THROW(read_all(reader), Error);
    const NodeRun run = run_mcap_check(file, dir / "cut-flipped.stderr");
    EXPECT_EQ(run.status, 1) << run.output << run.errors;
    EXPECT_NE(run.output.find("Incorrect chunk CRC"), std::string::npos) << run.output;
  }

  {  // an unchunked copy, as recordings written without chunks are: valid, every message read from
     // the front
    const fs::path file = dir / "unchunked.mcap";
    write_bytes(file, testing::unchunked(b));
    nlohmann::json j = check(file);
    EXPECT_EQ(j["complete"], true) << j.dump();
    EXPECT_EQ(j["messageCount"], kCount);
    EXPECT_EQ(j["indexed"]["chunkCount"], 0);
    EXPECT_EQ(j["indexed"]["messageCount"], 0) << "no chunks: nothing indexed";
    EXPECT_EQ(j["indexed"]["summaryOffsetOpcodes"].get<std::vector<int>>(), std::vector<int>{});
    EXPECT_NE(j["indexed"]["dataSectionCrcOk"], false) << j.dump();
  }

  {  // a session without messages
    const fs::path empty = dir / "empty.mcap";
    { McapWriter writer(empty); }
    nlohmann::json j = check(empty);
    EXPECT_EQ(j["complete"], true) << j.dump();
    EXPECT_EQ(j["messageCount"], 0);
  }
}

}  // namespace
}  // namespace cohaptic::record
