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
    throw Error(
        fmt::format("cannot open MCAP file {} for writing: {}", path_.string(), reason(error)));
  }
  // Our own buffer decides when bytes reach the file; stdio adds no second one.
  std::setvbuf(file_.get(), nullptr, _IONBF, 0);
  chunk_.reserve(std::min(options_.flush_bytes, std::size_t{1} << 20) + 4096);

  ByteBuffer header;
  put_bytes(header, kMcapMagic);
  const std::size_t start = begin_record(header, opcode::kHeader);
  put_string(header, "");  // profile: none of the well-known ones applies to protobuf
  put_string(header, kLibrary);
  end_record(header, start);
  write_now(header, true);
  last_flush_ = std::chrono::steady_clock::now();
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
    throw Error(fmt::format("MCAP writer for {} is unusable after an earlier error: {}",
                            path_.string(), failure_));
  }
  if (state_ == State::closed)
    throw Error(fmt::format("MCAP writer for {} is already closed", path_.string()));
}

void McapWriter::fail(std::string_view operation) {
  const int error = errno;
  state_ = State::failed;
  failure_ = fmt::format("cannot {} MCAP file {}: {}", operation, path_.string(), reason(error));
  chunk_.clear();
  throw Error(failure_);
}

std::uint16_t McapWriter::add_schema(std::string_view name, std::string_view encoding,
                                     std::string_view data) {
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
    throw Error(fmt::format("MCAP file {}: channel '{}' refers to unknown schema {}",
                            path_.string(), topic, schema_id));
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
  chunk_entries_.emplace_back();
  maybe_flush();
  return id;
}

void McapWriter::write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                       std::uint64_t publish_time_ns, std::span<const std::uint8_t> data) {
  check_usable();
  if (channel_id == 0 || channel_id > channel_records_.size()) {
    throw Error(
        fmt::format("MCAP file {}: message on unknown channel {}", path_.string(), channel_id));
  }
  start_chunk();
  const std::size_t start = chunk_.size();
  put_u8(chunk_, opcode::kMessage);
  put_u64(chunk_, kMessageFixedBytes + data.size());
  put_u16(chunk_, channel_id);
  put_u32(chunk_, sequence);
  put_u64(chunk_, log_time_ns);
  put_u64(chunk_, publish_time_ns);
  put_bytes(chunk_, data);

  std::vector<IndexEntry>& entries = chunk_entries_[channel_id - 1];
  if (entries.empty()) {
    chunk_channels_.push_back(channel_id);
    index_bytes_ += kRecordPrefixBytes + 2 + 4;  // channel_id, the entries' byte length
  }
  entries.push_back({log_time_ns, start - kRecordPrefixBytes - kChunkFieldsBytes});
  index_bytes_ += kMessageIndexEntryBytes;
  if (chunk_message_count_ == 0) {
    chunk_start_time_ = chunk_end_time_ = log_time_ns;
  } else {
    chunk_start_time_ = std::min(chunk_start_time_, log_time_ns);
    chunk_end_time_ = std::max(chunk_end_time_, log_time_ns);
  }
  ++chunk_message_count_;
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
                       std::uint64_t publish_time_ns,
                       const google::protobuf::MessageLite& message) {
  check_usable();
  const std::size_t size = message.ByteSizeLong();
  if (size > static_cast<std::size_t>(INT_MAX)) {
    throw Error(fmt::format("MCAP file {}: a {} of {} bytes is too large for protobuf",
                            path_.string(), message.GetTypeName(), size));
  }
  scratch_.resize(size);
  if (!message.SerializeToArray(scratch_.data(), static_cast<int>(size))) {
    throw Error(
        fmt::format("MCAP file {}: cannot serialize a {}", path_.string(), message.GetTypeName()));
  }
  write(channel_id, sequence, log_time_ns, publish_time_ns, scratch_);
}

void McapWriter::append(std::span<const std::uint8_t> record) {
  start_chunk();
  chunk_.insert(chunk_.end(), record.begin(), record.end());
}

void McapWriter::start_chunk() {
  if (chunk_.empty()) chunk_.resize(kRecordPrefixBytes + kChunkFieldsBytes);
}

std::uint64_t McapWriter::buffered_bytes() const {
  return chunk_.empty() ? 0 : chunk_.size() + index_bytes_;
}

void McapWriter::maybe_flush() {
  if (buffered_bytes() >= options_.flush_bytes ||
      std::chrono::steady_clock::now() - last_flush_ >= options_.flush_interval) {
    flush();
  }
}

void McapWriter::write_now(std::span<const std::uint8_t> bytes, bool in_data_section) {
  if (in_data_section) data_crc_.update(bytes);
  errno = 0;
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_.get()) != bytes.size()) fail("write");
  if (std::fflush(file_.get()) != 0) fail("flush");
  offset_ += bytes.size();
}

void McapWriter::write_chunk() {
  const std::uint64_t chunk_start = offset_;
  const std::size_t head_bytes = kRecordPrefixBytes + kChunkFieldsBytes;
  const std::uint64_t records_size = chunk_.size() - head_bytes;
  ByteBuffer head;
  head.reserve(head_bytes);
  put_u8(head, opcode::kChunk);
  put_u64(head, kChunkFieldsBytes + records_size);
  put_u64(head, chunk_start_time_);  // both 0 in a chunk without messages, as the spec asks
  put_u64(head, chunk_end_time_);
  put_u64(head, records_size);
  put_u32(head, crc32(std::span<const std::uint8_t>(chunk_).subspan(head_bytes)));
  put_string(head,
             "");  // compression: none, so that every flush leaves records readable as they are
  put_u64(head, records_size);
  std::copy(head.begin(), head.end(), chunk_.begin());
  const std::uint64_t chunk_length = chunk_.size();

  // The Message Index records follow the chunk, by channel id.
  std::sort(chunk_channels_.begin(), chunk_channels_.end());
  std::vector<std::pair<std::uint16_t, std::uint64_t>>
      index_offsets;  // channel, file offset of its index
  for (const std::uint16_t channel : chunk_channels_) {
    index_offsets.emplace_back(channel, chunk_start + chunk_.size());
    std::vector<IndexEntry>& entries = chunk_entries_[channel - 1];
    const std::size_t start = begin_record(chunk_, opcode::kMessageIndex);
    put_u16(chunk_, channel);
    put_u32(chunk_, static_cast<std::uint32_t>(entries.size() * kMessageIndexEntryBytes));
    for (const IndexEntry& entry : entries) {
      put_u64(chunk_, entry.log_time_ns);
      put_u64(chunk_, entry.offset);
    }
    end_record(chunk_, start);
    entries.clear();
  }
  write_now(chunk_, true);

  const std::size_t start = begin_record(chunk_indexes_, opcode::kChunkIndex);
  put_u64(chunk_indexes_, chunk_start_time_);
  put_u64(chunk_indexes_, chunk_end_time_);
  put_u64(chunk_indexes_, chunk_start);
  put_u64(chunk_indexes_, chunk_length);
  put_u32(chunk_indexes_, static_cast<std::uint32_t>(index_offsets.size() * (2 + 8)));
  for (const auto& [channel, offset] : index_offsets) {
    put_u16(chunk_indexes_, channel);
    put_u64(chunk_indexes_, offset);
  }
  put_u64(chunk_indexes_, chunk_.size() - chunk_length);  // message_index_length
  put_string(chunk_indexes_, "");
  put_u64(chunk_indexes_, records_size);  // compressed_size
  put_u64(chunk_indexes_, records_size);  // uncompressed_size
  end_record(chunk_indexes_, start);
  ++chunk_count_;

  chunk_.clear();
  chunk_channels_.clear();
  chunk_message_count_ = 0;
  chunk_start_time_ = chunk_end_time_ = 0;
  index_bytes_ = 0;
}

void McapWriter::flush() {
  if (state_ == State::closed) return;
  check_usable();
  if (!chunk_.empty()) write_chunk();
  last_flush_ = std::chrono::steady_clock::now();
}

void McapWriter::flush_if_due() {
  if (state_ == State::closed) return;
  check_usable();
  if (!chunk_.empty() && std::chrono::steady_clock::now() - last_flush_ >= options_.flush_interval)
    flush();
}

void McapWriter::close() {
  if (state_ == State::closed) return;
  check_usable();
  flush();

  // Everything after Data End is outside the data section: it does not feed data_crc_.
  ByteBuffer tail;
  std::size_t start = begin_record(tail, opcode::kDataEnd);
  put_u32(tail, data_crc_.value());
  end_record(tail, start);

  const std::uint64_t base = offset_;  // file offset of tail[0]
  const std::size_t summary_begin = tail.size();
  struct Group {
    std::uint8_t opcode;
    std::uint64_t start;
    std::uint64_t length;
  };
  std::vector<Group> groups;
  // Appends one group of records of opcode `op` (by calling put_records), if there are any.
  const auto add_group = [&](std::uint8_t op, const auto& put_records) {
    const std::size_t group_begin = tail.size();
    put_records();
    if (tail.size() > group_begin)
      groups.push_back({op, base + group_begin, tail.size() - group_begin});
  };
  add_group(opcode::kSchema, [&] {
    for (const auto& record : schema_records_) put_bytes(tail, record);
  });
  add_group(opcode::kChannel, [&] {
    for (const auto& record : channel_records_) put_bytes(tail, record);
  });
  add_group(opcode::kStatistics, [&] {
    const std::size_t statistics = begin_record(tail, opcode::kStatistics);
    put_u64(tail, message_count_);
    put_u16(tail, static_cast<std::uint16_t>(schema_records_.size()));
    put_u32(tail, static_cast<std::uint32_t>(channel_records_.size()));
    put_u32(tail, 0);  // attachments
    put_u32(tail, 0);  // metadata records
    put_u32(tail, chunk_count_);
    put_u64(tail, message_start_time_);
    put_u64(tail, message_end_time_);
    put_u32(tail, static_cast<std::uint32_t>(channel_message_counts_.size() * (2 + 8)));
    for (std::size_t i = 0; i < channel_message_counts_.size(); ++i) {
      put_u16(tail, static_cast<std::uint16_t>(i + 1));
      put_u64(tail, channel_message_counts_[i]);
    }
    end_record(tail, statistics);
  });
  add_group(opcode::kChunkIndex, [&] { put_bytes(tail, chunk_indexes_); });

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

  // Data End is the data section's last record, but its own bytes are outside its CRC.
  write_now(tail, false);
  errno = 0;
  if (std::fclose(file_.release()) != 0) fail("close");
  state_ = State::closed;
}

}  // namespace cohaptic::record
