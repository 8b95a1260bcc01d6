#include "proto/record/mcap_writer.h"

#include <fmt/format.h>
#include <google/protobuf/message_lite.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <limits>

#include "common/util/error.h"
#include "proto/record/mcap_bytes.h"
#include "proto/record/mcap_format.h"
#include "proto/record/protobuf_schema.h"

namespace cohaptic::record {
namespace {

constexpr std::string_view kLibrary = "cohaptic";

std::string reason(int error) { return error != 0 ? std::strerror(error) : "unknown error"; }

}  // namespace

void McapWriter::FileCloser::operator()(std::FILE* file) const { std::fclose(file); }

McapWriter::McapWriter(std::filesystem::path path, McapWriterOptions options)
    : path_(std::move(path)), options_(options) {
  file_.reset(std::fopen(path_.c_str(), "wb"));
  if (!file_) {
    const int error = errno;
    throw Error(fmt::format("cannot open MCAP file {} for writing: {}", path_.string(), reason(error)));
  }
  // Our own buffer decides when bytes reach the file; stdio adds no second one.
  std::setvbuf(file_.get(), nullptr, _IONBF, 0);
  pending_.reserve(std::min(options_.flush_bytes, std::size_t{1} << 20) + 4096);

  ByteBuffer header;
  put_bytes(header, kMcapMagic);
  const std::size_t start = begin_record(header, opcode::kHeader);
  put_string(header, "");  // profile: none of the well-known ones applies to protobuf
  put_string(header, kLibrary);
  end_record(header, start);
  append(header);
  flush();
}

McapWriter::~McapWriter() {
  if (state_ != State::open) return;
  try {
    close();
  } catch (const std::exception& e) {
    spdlog::error("MCAP recording not closed cleanly: {}", e.what());
  }
}

void McapWriter::check_usable() const {
  if (state_ == State::failed) {
    throw Error(fmt::format("MCAP writer for {} is unusable after an earlier error: {}", path_.string(), failure_));
  }
  if (state_ == State::closed) throw Error(fmt::format("MCAP writer for {} is already closed", path_.string()));
}

void McapWriter::fail(std::string_view operation) {
  const int error = errno;
  state_ = State::failed;
  failure_ = fmt::format("cannot {} MCAP file {}: {}", operation, path_.string(), reason(error));
  pending_.clear();
  throw Error(failure_);
}

std::uint16_t McapWriter::add_schema(std::string_view name, std::string_view encoding, std::string_view data) {
  check_usable();
  if (schema_records_.size() >= std::numeric_limits<std::uint16_t>::max()) {
    throw Error(fmt::format("MCAP file {}: too many schemas (at most 65535)", path_.string()));
  }
  const auto id = static_cast<std::uint16_t>(schema_records_.size() + 1);
  ByteBuffer record;
  const std::size_t start = begin_record(record, opcode::kSchema);
  put_u16(record, id);
  put_string(record, name);
  put_string(record, encoding);
  put_string(record, data);  // uint32 length-prefixed bytes, the same layout as a String
  end_record(record, start);
  append(record);
  schema_records_.push_back(std::move(record));
  maybe_flush();
  return id;
}

std::uint16_t McapWriter::add_protobuf_schema(const google::protobuf::Descriptor* descriptor) {
  return add_schema(schema_name(descriptor), "protobuf", protobuf_schema_data(descriptor));
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, std::string_view topic,
                                      std::string_view message_encoding,
                                      const std::map<std::string, std::string>& metadata) {
  check_usable();
  if (schema_id > schema_records_.size()) {
    throw Error(fmt::format("MCAP file {}: channel '{}' refers to unknown schema {}", path_.string(), topic, schema_id));
  }
  if (channel_records_.size() >= std::numeric_limits<std::uint16_t>::max()) {
    throw Error(fmt::format("MCAP file {}: too many channels (at most 65535)", path_.string()));
  }
  const auto id = static_cast<std::uint16_t>(channel_records_.size() + 1);
  ByteBuffer record;
  const std::size_t start = begin_record(record, opcode::kChannel);
  put_u16(record, id);
  put_u16(record, schema_id);
  put_string(record, topic);
  put_string(record, message_encoding);
  put_string_map(record, metadata);
  end_record(record, start);
  append(record);
  channel_records_.push_back(std::move(record));
  channel_message_counts_.push_back(0);
  maybe_flush();
  return id;
}

void McapWriter::write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                       std::uint64_t publish_time_ns, std::span<const std::uint8_t> data) {
  check_usable();
  if (channel_id == 0 || channel_id > channel_records_.size()) {
    throw Error(fmt::format("MCAP file {}: message on unknown channel {}", path_.string(), channel_id));
  }
  const std::size_t start = pending_.size();
  put_u8(pending_, opcode::kMessage);
  put_u64(pending_, kMessageFixedBytes + data.size());
  put_u16(pending_, channel_id);
  put_u32(pending_, sequence);
  put_u64(pending_, log_time_ns);
  put_u64(pending_, publish_time_ns);
  put_bytes(pending_, data);
  data_crc_.update(std::span<const std::uint8_t>(pending_).subspan(start));

  if (message_count_ == 0) {
    message_start_time_ = message_end_time_ = log_time_ns;
  } else {
    message_start_time_ = std::min(message_start_time_, log_time_ns);
    message_end_time_ = std::max(message_end_time_, log_time_ns);
  }
  ++message_count_;
  ++channel_message_counts_[channel_id - 1];
  maybe_flush();
}

void McapWriter::write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                       std::uint64_t publish_time_ns, const google::protobuf::MessageLite& message) {
  check_usable();
  const std::size_t size = message.ByteSizeLong();
  if (size > static_cast<std::size_t>(INT_MAX)) {
    throw Error(fmt::format("MCAP file {}: a {} of {} bytes is too large for protobuf", path_.string(),
                            message.GetTypeName(), size));
  }
  scratch_.resize(size);
  if (!message.SerializeToArray(scratch_.data(), static_cast<int>(size))) {
    throw Error(fmt::format("MCAP file {}: cannot serialize a {}", path_.string(), message.GetTypeName()));
  }
  write(channel_id, sequence, log_time_ns, publish_time_ns, scratch_);
}

void McapWriter::append(std::span<const std::uint8_t> record) {
  data_crc_.update(record);
  pending_.insert(pending_.end(), record.begin(), record.end());
}

void McapWriter::maybe_flush() {
  if (pending_.size() >= options_.flush_bytes ||
      std::chrono::steady_clock::now() - last_flush_ >= options_.flush_interval) {
    flush();
  }
}

void McapWriter::write_now(std::span<const std::uint8_t> bytes) {
  errno = 0;
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_.get()) != bytes.size()) fail("write");
  if (std::fflush(file_.get()) != 0) fail("flush");
  offset_ += bytes.size();
}

void McapWriter::flush() {
  if (state_ == State::closed) return;
  check_usable();
  if (!pending_.empty()) {
    write_now(pending_);
    pending_.clear();
  }
  last_flush_ = std::chrono::steady_clock::now();
}

void McapWriter::flush_if_due() {
  if (state_ == State::closed) return;
  check_usable();
  if (!pending_.empty() && std::chrono::steady_clock::now() - last_flush_ >= options_.flush_interval) flush();
}

void McapWriter::close() {
  if (state_ == State::closed) return;
  check_usable();

  // Everything from here on is outside the data section: it does not feed data_crc_.
  ByteBuffer tail;
  std::size_t start = begin_record(tail, opcode::kDataEnd);
  put_u32(tail, data_crc_.value());
  end_record(tail, start);

  const std::uint64_t base = size();  // file offset of tail[0]
  const std::size_t summary_begin = tail.size();
  struct Group {
    std::uint8_t opcode;
    std::uint64_t start;
    std::uint64_t length;
  };
  std::vector<Group> groups;
  const auto add_group = [&](std::uint8_t op, const std::vector<ByteBuffer>& records) {
    if (records.empty()) return;
    const std::size_t group_begin = tail.size();
    for (const auto& record : records) put_bytes(tail, record);
    groups.push_back({op, base + group_begin, tail.size() - group_begin});
  };
  add_group(opcode::kSchema, schema_records_);
  add_group(opcode::kChannel, channel_records_);

  ByteBuffer statistics;
  start = begin_record(statistics, opcode::kStatistics);
  put_u64(statistics, message_count_);
  put_u16(statistics, static_cast<std::uint16_t>(schema_records_.size()));
  put_u32(statistics, static_cast<std::uint32_t>(channel_records_.size()));
  put_u32(statistics, 0);  // attachments
  put_u32(statistics, 0);  // metadata records
  put_u32(statistics, 0);  // chunks
  put_u64(statistics, message_start_time_);
  put_u64(statistics, message_end_time_);
  put_u32(statistics, static_cast<std::uint32_t>(channel_message_counts_.size() * (2 + 8)));
  for (std::size_t i = 0; i < channel_message_counts_.size(); ++i) {
    put_u16(statistics, static_cast<std::uint16_t>(i + 1));
    put_u64(statistics, channel_message_counts_[i]);
  }
  end_record(statistics, start);
  add_group(opcode::kStatistics, {statistics});

  const std::size_t summary_offset_begin = tail.size();
  for (const Group& group : groups) {
    start = begin_record(tail, opcode::kSummaryOffset);
    put_u8(tail, group.opcode);
    put_u64(tail, group.start);
    put_u64(tail, group.length);
    end_record(tail, start);
  }

  // Its length written up front: the summary CRC covers the summary, the summary offsets
  // and the Footer up to (not including) the CRC itself.
  put_u8(tail, opcode::kFooter);
  put_u64(tail, kFooterContentBytes);
  put_u64(tail, base + summary_begin);
  put_u64(tail, base + summary_offset_begin);
  put_u32(tail, crc32(std::span<const std::uint8_t>(tail).subspan(summary_begin)));
  put_bytes(tail, kMcapMagic);

  pending_.insert(pending_.end(), tail.begin(), tail.end());
  flush();
  errno = 0;
  if (std::fclose(file_.release()) != 0) fail("close");
  state_ = State::closed;
}

}  // namespace cohaptic::record
