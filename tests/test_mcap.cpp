// Recordings (proto/record/): the MCAP writer and reader. A round trip of thousands of
// protobuf messages; the bytes on disk checked field by field against the spec with a
// parser and a CRC written here, independent of the library; the protobuf schema decoding a
// recorded message through DynamicMessageFactory; truncation at thousands of cut points;
// a writer killed mid-session (fork + SIGKILL / _exit); write errors (/dev/full, a file
// size limit hit mid-session); files the reader must reject or skip over; and the official
// TypeScript reader (@mcap/core) reading our files (tests/support/mcap_check.mjs).
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
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "common/util/error.h"
#include "proto/record/crc32.h"
#include "proto/record/mcap_reader.h"
#include "proto/record/mcap_writer.h"
#include "proto/record/protobuf_schema.h"
#include "support/process.h"
#include "support/test_meshes.h"

namespace cohaptic::record {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;
using namespace std::chrono_literals;

// ---- independent helpers: byte access, CRC and record walking written here ----

Bytes read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_bytes(const fs::path& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

std::uint64_t le(const Bytes& b, std::size_t at, int width) {
  std::uint64_t value = 0;
  for (int i = width - 1; i >= 0; --i) value = (value << 8) | b.at(at + static_cast<std::size_t>(i));
  return value;
}
std::uint16_t le16(const Bytes& b, std::size_t at) { return static_cast<std::uint16_t>(le(b, at, 2)); }
std::uint32_t le32(const Bytes& b, std::size_t at) { return static_cast<std::uint32_t>(le(b, at, 4)); }
std::uint64_t le64(const Bytes& b, std::size_t at) { return le(b, at, 8); }
std::string text(const Bytes& b, std::size_t at, std::size_t n) {
  return std::string(reinterpret_cast<const char*>(b.data() + at), n);
}

// Bit by bit, as the definition goes (the library uses tables).
std::uint32_t reference_crc(const Bytes& b, std::size_t begin, std::size_t end) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = begin; i < end; ++i) {
    c ^= b[i];
    for (int bit = 0; bit < 8; ++bit) c = (c & 1u) ? (c >> 1) ^ 0xEDB88320u : c >> 1;
  }
  return ~c;
}

const std::string kMagic("\x89MCAP0\r\n", 8);

struct RawRecord {
  std::size_t offset;
  std::uint8_t opcode;
  std::uint64_t length;  // content
  std::size_t content() const { return offset + 9; }
  std::size_t end() const { return offset + 9 + static_cast<std::size_t>(length); }
};

// The records after the opening magic, up to and including the Footer.
std::vector<RawRecord> walk(const Bytes& b) {
  std::vector<RawRecord> records;
  std::size_t at = 8;
  while (at + 9 <= b.size()) {
    RawRecord r{at, b[at], le64(b, at + 1)};
    records.push_back(r);
    at = r.end();
    if (r.opcode == 0x02) break;
  }
  return records;
}

// Appends MCAP fields for hand-made files.
struct Builder {
  Bytes out;
  Builder& u8(std::uint8_t v) { out.push_back(v); return *this; }
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
    case 0: m.channel_id = c.tool; m.data = serialized(tool_sample(i)); break;
    case 1: m.channel_id = c.datagram; m.data = serialized(datagram(i)); break;
    default: m.channel_id = c.force; m.data = serialized(force_sample(i)); break;
  }
  return m;
}

// Writes messages [first, first + count); ToolSample by the protobuf overload, the others as bytes.
void write_messages(McapWriter& writer, const Channels& c, std::uint32_t first, std::uint32_t count) {
  for (std::uint32_t i = first; i < first + count; ++i) {
    const McapMessage m = expected_message(c, i);
    if (i % 3 == 0) {
      writer.write(m.channel_id, m.sequence, m.log_time_ns, m.publish_time_ns, tool_sample(i));
    } else {
      writer.write(m.channel_id, m.sequence, m.log_time_ns, m.publish_time_ns, m.data);
    }
  }
}

Channels record_session(const fs::path& path, std::uint32_t count) {
  McapWriter writer(path);
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
    for (const auto& part : parts) EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

// ---- CRC ----

TEST(McapCrc32, MatchesTheStandardCheckValueAndTheBitwiseDefinition) {
  const std::string check = "123456789";
  EXPECT_EQ(crc32({reinterpret_cast<const std::uint8_t*>(check.data()), check.size()}), 0xCBF43926u);
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
      EXPECT_FALSE(reader.parse<wire::ForceSample>(*m).has_value()) << "a ToolSample channel parsed as ForceSample";
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
  EXPECT_EQ(s.chunk_count, 0u);
  EXPECT_EQ(s.message_start_time_ns, kEpochNs);
  EXPECT_EQ(s.message_end_time_ns, kEpochNs + std::uint64_t{kCount - 1} * 1'000'000);
  EXPECT_EQ(s.channel_message_counts, per_channel);
  EXPECT_FALSE(reader.next().has_value()) << "next() after the end stays at the end";
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

TEST(McapLayout, RecordsSummaryAndFooterFollowTheSpec) {
  const fs::path file = testing::scratch_directory("mcap-layout") / "layout.mcap";
  const std::string schema_data = protobuf_schema_data(wire::ToolSample::descriptor());
  {
    McapWriter writer(file);
    EXPECT_EQ(writer.add_protobuf_schema(wire::ToolSample::descriptor()), 1);
    EXPECT_EQ(writer.add_channel(1, "/tool", "protobuf", {{"user", "0"}}), 1);
    writer.write(1, 7, 0x0102030405060708ull, 0x0102030405060700ull, Bytes{0xAA, 0xBB, 0xCC});
    writer.write(1, 8, 2000, 1900, Bytes{});
    EXPECT_EQ(writer.message_count(), 2u);
    writer.close();
    EXPECT_TRUE(writer.is_closed());
  }
  const Bytes b = read_bytes(file);
  ASSERT_GT(b.size(), 16u);
  EXPECT_EQ(text(b, 0, 8), kMagic);
  EXPECT_EQ(text(b, b.size() - 8, 8), kMagic);

  const std::vector<RawRecord> r = walk(b);
  // Header, Schema, Channel, 2 Messages, Data End; summary: Schema, Channel, Statistics;
  // 3 Summary Offsets; Footer.
  std::vector<int> opcodes;
  for (const auto& record : r) opcodes.push_back(record.opcode);
  EXPECT_EQ(opcodes, (std::vector<int>{0x01, 0x03, 0x04, 0x05, 0x05, 0x0F, 0x03, 0x04, 0x0B, 0x0E, 0x0E, 0x0E, 0x02}));
  ASSERT_EQ(r.size(), 13u);
  EXPECT_EQ(r.back().end() + 8, b.size()) << "the Footer is followed by the magic and nothing else";

  // Header: profile "", library "cohaptic".
  EXPECT_EQ(r[0].offset, 8u);
  EXPECT_EQ(r[0].length, 4u + 0 + 4 + 8);
  EXPECT_EQ(le32(b, r[0].content()), 0u);
  EXPECT_EQ(le32(b, r[0].content() + 4), 8u);
  EXPECT_EQ(text(b, r[0].content() + 8, 8), "cohaptic");

  // Schema: id, name, encoding, u32-prefixed data.
  std::size_t at = r[1].content();
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
  EXPECT_EQ(r[1].length, 2 + 4 + name.size() + 4 + 8 + 4 + schema_data.size());

  // Channel: id, schema id, topic, message encoding, Map<string, string>.
  at = r[2].content();
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
  EXPECT_EQ(r[2].length, 42u);

  // Message: channel, sequence, log time, publish time, data; little-endian on disk.
  at = r[3].content();
  EXPECT_EQ(r[3].length, 22u + 3);
  EXPECT_EQ(le16(b, at), 1);
  EXPECT_EQ(le32(b, at + 2), 7u);
  EXPECT_EQ((Bytes(b.begin() + static_cast<long>(at) + 6, b.begin() + static_cast<long>(at) + 14)),
            (Bytes{0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01}));
  EXPECT_EQ(le64(b, at + 14), 0x0102030405060700ull);
  EXPECT_EQ((Bytes(b.begin() + static_cast<long>(at) + 22, b.begin() + static_cast<long>(r[3].end()))),
            (Bytes{0xAA, 0xBB, 0xCC}));
  EXPECT_EQ(r[4].length, 22u);
  EXPECT_EQ(le32(b, r[4].content() + 2), 8u);

  // Data End: the CRC of every byte before it.
  EXPECT_EQ(r[5].length, 4u);
  EXPECT_EQ(le32(b, r[5].content()), reference_crc(b, 0, r[5].offset));

  // Summary: the Schema and Channel records again, byte for byte, then Statistics.
  const auto bytes_of = [&](const RawRecord& record) {
    return Bytes(b.begin() + static_cast<long>(record.offset), b.begin() + static_cast<long>(record.end()));
  };
  EXPECT_EQ(bytes_of(r[6]), bytes_of(r[1]));
  EXPECT_EQ(bytes_of(r[7]), bytes_of(r[2]));
  at = r[8].content();
  EXPECT_EQ(le64(b, at), 2u) << "message_count";
  EXPECT_EQ(le16(b, at + 8), 1) << "schema_count";
  EXPECT_EQ(le32(b, at + 10), 1u) << "channel_count";
  EXPECT_EQ(le32(b, at + 14), 0u) << "attachment_count";
  EXPECT_EQ(le32(b, at + 18), 0u) << "metadata_count";
  EXPECT_EQ(le32(b, at + 22), 0u) << "chunk_count";
  EXPECT_EQ(le64(b, at + 26), 2000u) << "message_start_time";
  EXPECT_EQ(le64(b, at + 34), 0x0102030405060708ull) << "message_end_time";
  EXPECT_EQ(le32(b, at + 42), 10u) << "channel_message_counts byte length";
  EXPECT_EQ(le16(b, at + 46), 1);
  EXPECT_EQ(le64(b, at + 48), 2u);
  EXPECT_EQ(r[8].length, 56u);

  // Summary Offsets: one per group, pointing at it.
  const std::vector<std::pair<int, const RawRecord*>> groups = {{0x03, &r[6]}, {0x04, &r[7]}, {0x0B, &r[8]}};
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const RawRecord& offset = r[9 + g];
    EXPECT_EQ(offset.length, 17u);
    EXPECT_EQ(b[offset.content()], groups[g].first);
    EXPECT_EQ(le64(b, offset.content() + 1), groups[g].second->offset);
    EXPECT_EQ(le64(b, offset.content() + 9), groups[g].second->end() - groups[g].second->offset);
  }

  // Footer: summary start, summary offset start, and the CRC from the summary through
  // the Footer's summary_offset_start field.
  const RawRecord& footer = r[12];
  EXPECT_EQ(footer.offset, b.size() - 8 - 29) << "the Footer is the last record";
  EXPECT_EQ(footer.length, 20u);
  EXPECT_EQ(le64(b, footer.content()), r[6].offset);
  EXPECT_EQ(r[6].offset, r[5].end()) << "the summary starts right after Data End";
  EXPECT_EQ(le64(b, footer.content() + 8), r[9].offset);
  EXPECT_EQ(le32(b, footer.content() + 16), reference_crc(b, r[6].offset, footer.content() + 16));
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
  ASSERT_TRUE(message->ParseFromArray(recorded->data.data(), static_cast<int>(recorded->data.size())));

  const auto* reflection = message->GetReflection();
  const auto& header = reflection->GetMessage(*message, type->FindFieldByName("header"));
  EXPECT_EQ(header.GetReflection()->GetUInt64(header, header.GetDescriptor()->FindFieldByName("sequence")), 10u);
  EXPECT_EQ(header.GetReflection()->GetUInt64(header, header.GetDescriptor()->FindFieldByName("session")),
            0x5e55'1000'0001u);
  const google::protobuf::FieldDescriptor* tool_field = type->FindFieldByName("tool");
  ASSERT_TRUE(reflection->HasField(*message, tool_field));
  const auto& tool = reflection->GetMessage(*message, tool_field);
  const auto& position = tool.GetReflection()->GetMessage(tool, tool.GetDescriptor()->FindFieldByName("position"));
  EXPECT_EQ(position.GetReflection()->GetDouble(position, position.GetDescriptor()->FindFieldByName("x")),
            tool_sample(10).position().x());
  EXPECT_EQ(position.GetReflection()->GetDouble(position, position.GetDescriptor()->FindFieldByName("z")),
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
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()),
            (std::set<std::string>{"google/protobuf/api.proto", "google/protobuf/type.proto",
                                   "google/protobuf/source_context.proto", "google/protobuf/any.proto"}));
  EXPECT_EQ(names.size(), 4u) << "each file once";
  EXPECT_EQ(names.back(), "google/protobuf/api.proto");
  google::protobuf::DescriptorPool pool;  // BuildFile fails on a file whose imports are not built yet
  for (const auto& f : set.file()) ASSERT_NE(pool.BuildFile(f), nullptr) << f.name() << " before its imports";
  EXPECT_NE(pool.FindMessageTypeByName("google.protobuf.Api"), nullptr);
}

// ---- truncation ----

TEST(McapTruncation, EveryCutYieldsExactlyTheMessagesCompleteBeforeIt) {
  const fs::path dir = testing::scratch_directory("mcap-truncation");
  const fs::path file = dir / "full.mcap";
  constexpr std::uint32_t kCount = 1000;
  const Channels c = record_session(file, kCount);
  const Bytes b = read_bytes(file);
  const std::vector<RawRecord> records = walk(b);

  std::vector<std::size_t> message_ends;
  std::vector<std::size_t> record_ends = {8};
  for (const auto& r : records) {
    if (r.opcode == 0x05) message_ends.push_back(r.end());
    record_ends.push_back(r.end());
  }
  record_ends.push_back(b.size());
  ASSERT_EQ(message_ends.size(), kCount);
  std::vector<McapMessage> expected;
  for (std::uint32_t i = 0; i < kCount; ++i) expected.push_back(expected_message(c, i));

  // Cut points: every byte of the first records and of the summary, footer and magic; the
  // edges of every 10th record (start, inside the prefix, just past it, last byte); and
  // every 37th byte elsewhere.
  std::set<std::size_t> cuts;
  for (std::size_t k = 0; k < 600 && k <= b.size(); ++k) cuts.insert(k);
  const auto first_of = [&](int opcode) {
    return std::find_if(records.begin(), records.end(), [&](const RawRecord& r) { return r.opcode == opcode; });
  };
  for (std::size_t k = message_ends.back() - 1; k <= first_of(0x0F)->end() + 200; ++k) cuts.insert(k);
  for (std::size_t k = first_of(0x0B)->offset; k <= b.size(); ++k) cuts.insert(k);
  for (std::size_t i = 0; i < records.size(); i += (i < 20 || i + 20 > records.size()) ? 1 : 10) {
    for (std::size_t d : {0, 1, 8, 9, 10}) cuts.insert(records[i].offset + d);
    cuts.insert(records[i].end() - 1);
  }
  for (std::size_t k = 0; k < b.size(); k += 37) cuts.insert(k);

  const fs::path cut_file = dir / "cut.mcap";
  fs::copy_file(file, cut_file);
  std::size_t checked = 0;
  for (auto it = cuts.rbegin(); it != cuts.rend(); ++it) {  // from the longest, shortening one file
    const std::size_t cut = *it;
    if (cut > b.size()) continue;
    fs::resize_file(cut_file, cut);
    SCOPED_TRACE("cut at byte " + std::to_string(cut) + " of " + std::to_string(b.size()));
    const std::size_t complete_messages =
        static_cast<std::size_t>(std::upper_bound(message_ends.begin(), message_ends.end(), cut) - message_ends.begin());
    const std::size_t valid = cut < 8 ? 0 : *(std::upper_bound(record_ends.begin(), record_ends.end(), cut) - 1);

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
    ++checked;
  }
  EXPECT_GT(checked, 3000u);
  std::printf("checked %zu cut points of a %zu-byte file\n", checked, b.size());

  // The descriptions say where the file ends.
  const auto cut_copy = [&](std::size_t n) { write_bytes(cut_file, Bytes(b.begin(), b.begin() + static_cast<long>(n))); };
  cut_copy(message_ends[499] + 12);
  McapReader mid(cut_file);
  EXPECT_EQ(read_all(mid).size(), 500u);
  EXPECT_EQ(mid.truncation(), "file ends 3 bytes into the content of a " +
                                  std::to_string(records[7 + 500].length) + "-byte Message record at offset " +
                                  std::to_string(message_ends[499]));
  cut_copy(message_ends[499]);
  McapReader boundary(cut_file);
  EXPECT_EQ(read_all(boundary).size(), 500u);
  EXPECT_EQ(boundary.truncation(), "file ends after the complete record ending at offset " +
                                       std::to_string(message_ends[499]) + ", without a Footer");
}

// ---- a writer that dies ----

void expect_crash_leaves_flushed_messages(bool kill) {
  const fs::path file = testing::scratch_directory(kill ? "mcap-killed" : "mcap-exited") / "crashed.mcap";
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
  for (std::uint32_t i = 0; i < kFlushed; ++i) ASSERT_EQ(got[i], expected_message(c, i)) << "message " << i;
  EXPECT_EQ(reader.channels().size(), 3u);
  EXPECT_EQ(reader.schemas().size(), 3u);
  EXPECT_TRUE(reader.truncated());
  EXPECT_FALSE(reader.complete());
  EXPECT_EQ(reader.valid_bytes(), fs::file_size(file)) << "flushed records are whole";
}

TEST(McapCrash, AWriterKilledMidSessionLeavesEveryFlushedMessage) { expect_crash_leaves_flushed_messages(true); }

TEST(McapCrash, AWriterExitingWithoutClosingLeavesEveryFlushedMessage) { expect_crash_leaves_flushed_messages(false); }

// ---- flushing ----

TEST(McapWriter, FlushesWhenTheBufferFillsWhenTimeIsUpAndOnRequest) {
  const fs::path dir = testing::scratch_directory("mcap-flush");
  const auto on_disk = [](const fs::path& p) { return static_cast<std::uint64_t>(fs::file_size(p)); };
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
  expect_error([] { McapWriter writer("/nonexistent-dir/x.mcap"); }, {"/nonexistent-dir/x.mcap", std::strerror(ENOENT)});
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
  for (ssize_t n; (n = ::read(pipe_fds[0], buffer, sizeof buffer)) > 0;) report.append(buffer, static_cast<std::size_t>(n));
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
  EXPECT_GT(got.size(), 500u);
  Channels c;
  c.tool = 1;
  c.datagram = 2;
  c.force = 3;
  for (std::uint32_t i = 0; i < got.size(); ++i) ASSERT_EQ(got[i], expected_message(c, i)) << "message " << i;
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
  expect_error([&] { McapReader reader(dir / "missing.mcap"); }, {(dir / "missing.mcap").string(), std::strerror(ENOENT)});
  expect_error([&] { McapReader reader(dir); }, {dir.string()});

  // An empty file, or a cut inside the magic, is a truncated recording, not a foreign file.
  const fs::path empty = dir / "empty.mcap";
  write_bytes(empty, Bytes{});
  McapReader reader(empty);
  EXPECT_FALSE(reader.next().has_value());
  EXPECT_TRUE(reader.truncated());
}

Bytes header_content() { return Builder{}.str("").str("hand-made").out; }
Bytes schema_content(std::uint16_t id) { return Builder{}.uint(id, 2).str("raw").str("").str("").out; }
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

TEST(McapReader, RejectsChunkedFiles) {
  const fs::path file = testing::scratch_directory("mcap-chunked") / "chunked.mcap";
  Builder b;
  b.magic().record(0x01, header_content());
  const Bytes records = Builder{}.record(0x03, schema_content(1)).record(0x04, channel_content(1, 1)).out;
  Builder chunk;
  chunk.uint(100, 8).uint(100, 8).uint(records.size(), 8).uint(0, 4).str("").uint(records.size(), 8);
  chunk.out.insert(chunk.out.end(), records.begin(), records.end());
  b.record(0x06, chunk.out).record(0x0F, Builder{}.uint(0, 4).out).record(0x02, footer_content()).magic();
  write_bytes(file, b.out);
  McapReader reader(file);
  expect_error([&] { reader.next(); }, {file.string(), "chunked MCAP files are not supported", "offset 34"});
  expect_error([&] { reader.next(); }, {"chunked"});  // and it stays failed
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
  b.record(0x09, Bytes(40, 0x11));       // an attachment: known, of no use here
  b.record(0x0C, Builder{}.str("info").uint(0, 4).out);  // metadata
  b.record(0x7E, Bytes{});               // a future MCAP record, empty
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
  const auto expect_rejected = [&](const std::string& name, const Bytes& bytes, const std::string& part) {
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
  start.magic().record(0x01, header_content()).record(0x03, schema_content(1)).record(0x04, channel_content(1, 1));

  Builder orphan = start;
  orphan.record(0x05, message_content(2, 1, "x"));
  expect_rejected("orphan.mcap", orphan.out, "message on channel 2, which no earlier Channel record defines");

  Builder short_record = start;
  short_record.record(0x05, Bytes{1, 0, 0});
  expect_rejected("short.mcap", short_record.out, "Message record at offset");

  Builder redefined = start;
  redefined.record(0x04, Builder{}.uint(1, 2).uint(1, 2).str("/other").str("raw").uint(0, 4).out);
  expect_rejected("redefined.mcap", redefined.out, "channel 1 ('/other') differs");

  Builder no_header;
  no_header.magic().record(0x03, schema_content(1));
  expect_rejected("no-header.mcap", no_header.out, "expected a Header record");

  // One flipped bit inside a message's data: the structure holds, the data-section CRC does not.
  const fs::path good = dir / "good.mcap";
  record_session(good, 100);
  Bytes corrupt = read_bytes(good);
  const std::vector<RawRecord> records = walk(corrupt);
  corrupt[records[60].content() + 23] ^= 0x04;
  expect_rejected("corrupt.mcap", corrupt, "data section CRC-32");
  Bytes corrupt_summary = read_bytes(good);
  corrupt_summary[corrupt_summary.size() - 8 - 29 - 40] ^= 0x01;  // a group_start in the Summary Offsets
  expect_rejected("corrupt-summary.mcap", corrupt_summary, "summary CRC-32");
}

// ---- the official reader ----

struct NodeRun {
  int status = -1;
  std::string output;
  std::string errors;
};

NodeRun run_mcap_check(const fs::path& file, const fs::path& errors) {
  const std::string command = "node '" + testing::source_path("tests/support/mcap_check.mjs") + "' '" +
                              file.string() + "' 2>'" + errors.string() + "'";
  NodeRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) run.output.append(buffer, n);
  const int status = ::pclose(pipe);
  run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(errors);
  run.errors.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return run;
}

TEST(McapWriter, TheOfficialReaderReadsOurFiles) {
  if (std::system("node --version > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "node is not installed; this check needs node (v18 or later) and @mcap/core: "
                    "install Debian's nodejs and npm, then npm ci --prefix deploy/node (deploy/install-deps.sh does both)";
  }
  if (!fs::exists(testing::source_path("deploy/node/node_modules/@mcap/core/package.json"))) {
    GTEST_SKIP() << "@mcap/core is not installed; from the source tree run: npm ci --prefix deploy/node (deploy/install-deps.sh does)";
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
      ADD_FAILURE() << "mcap_check.mjs printed no JSON (" << e.what() << "): " << run.output << run.errors;
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
    EXPECT_EQ(indexed["chunkCount"], 0);
    EXPECT_EQ(indexed["summaryOffsetOpcodes"].get<std::vector<int>>(), (std::vector<int>{0x03, 0x04, 0x0B}));
    EXPECT_EQ(indexed["statistics"]["messageCount"], kCount);
    EXPECT_EQ(indexed["statistics"]["channelCount"], 3);
    EXPECT_EQ(indexed["statistics"]["messageStartTime"], std::to_string(kEpochNs));
    for (const auto& topic : topics) {
      EXPECT_EQ(indexed["statistics"]["channelMessageCounts"][topic], kCount / 3) << topic;
      EXPECT_EQ(j["channelMessageCounts"][topic], kCount / 3) << topic;
    }
    // Recomputed with Node's zlib when it has crc32 (Node 20.15 and later).
    EXPECT_NE(indexed["dataSectionCrcOk"], false) << j.dump();
  }

  const Bytes b = read_bytes(full);
  const std::vector<RawRecord> records = walk(b);
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
    EXPECT_FALSE(j["indexError"].is_null()) << "the indexed reader should refuse a file without a footer";
    EXPECT_EQ(j["messageCount"], ours) << j.dump();
    EXPECT_EQ(j["channels"].get<std::vector<std::string>>(), topics);
    return ours;
  };
  // Inside the 1501st message (records: Header, 3 Schemas, 3 Channels, then messages).
  const RawRecord& inside = records[7 + 1500];
  ASSERT_EQ(inside.opcode, 0x05);
  EXPECT_EQ(official_and_ours_agree_on_a_cut(inside.offset + 20, "cut-inside.mcap"), 1500u);
  // Right after the 1000th message, as a crashed writer leaves it.
  EXPECT_EQ(official_and_ours_agree_on_a_cut(records[7 + 999].end(), "cut-boundary.mcap"), 1000u);

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
