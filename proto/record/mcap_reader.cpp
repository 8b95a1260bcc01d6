#include "proto/record/mcap_reader.h"

#include <fmt/format.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <utility>

#include "common/util/error.h"
#include "proto/record/mcap_bytes.h"
#include "proto/record/mcap_format.h"

namespace cohaptic::record {
namespace {

std::uint64_t le64(const std::uint8_t* bytes) {
  std::uint64_t value = 0;
  for (int i = 7; i >= 0; --i) value = (value << 8) | bytes[i];
  return value;
}

// The records the spec allows inside a Chunk; every other opcode it defines is misplaced there.
bool belongs_in_chunk(std::uint8_t op) {
  return op == opcode::kSchema || op == opcode::kChannel || op == opcode::kMessage;
}
bool defined_by_spec(std::uint8_t op) { return op >= opcode::kHeader && op <= opcode::kDataEnd; }

}  // namespace

void McapReader::FileCloser::operator()(std::FILE* file) const { std::fclose(file); }

McapReader::McapReader(std::filesystem::path path) : path_(std::move(path)) {
  file_.reset(std::fopen(path_.c_str(), "rb"));
  if (!file_) {
    const int error = errno;
    throw Error(fmt::format("cannot open MCAP file {}: {}", path_.string(), std::strerror(error)));
  }
  struct stat info {};
  if (::fstat(::fileno(file_.get()), &info) != 0) fail_io("stat");
  file_size_ = static_cast<std::uint64_t>(std::max<off_t>(info.st_size, 0));
  std::setvbuf(file_.get(), nullptr, _IOFBF, std::size_t{1} << 16);

  read_magic();
  if (state_ != State::reading) return;
  if (!read_record()) return;
  if (prefix_[0] != opcode::kHeader) {
    throw Error(fmt::format("{}: expected a Header record after the magic, found a {} record",
                            path_.string(), mcap_opcode_name(prefix_[0])));
  }
  dispatch_record();
}

void McapReader::fail_io(const char* operation) {
  const int error = errno;
  throw Error(fmt::format("cannot {} MCAP file {}: {}", operation, path_.string(),
                          error != 0 ? std::strerror(error) : "unknown error"));
}

void McapReader::read_magic() {
  std::uint8_t magic[8] = {};
  errno = 0;
  const std::size_t got = std::fread(magic, 1, sizeof magic, file_.get());
  if (got < sizeof magic && std::ferror(file_.get())) fail_io("read");
  const bool prefix_matches =
      std::equal(magic, magic + std::min<std::size_t>(got, 5), kMcapMagic.begin());
  if (got < sizeof magic && prefix_matches && std::equal(magic, magic + got, kMcapMagic.begin())) {
    end_truncated(fmt::format("file ends after {} of the 8 bytes of the opening magic", got));
    return;
  }
  if (got == sizeof magic && prefix_matches && magic[5] != kMcapMagic[5]) {
    throw Error(fmt::format("{}: unsupported MCAP major version '{}' (this reader reads version 0)",
                            path_.string(), static_cast<char>(magic[5])));
  }
  if (got < sizeof magic || !std::equal(magic, magic + sizeof magic, kMcapMagic.begin())) {
    throw Error(
        fmt::format("{}: not an MCAP file (it does not start with the MCAP magic \\x89MCAP0\\r\\n)",
                    path_.string()));
  }
  data_crc_.update(magic);
  offset_ = sizeof magic;
}

void McapReader::end_truncated(std::string how) {
  state_ = State::ended;
  truncated_ = true;
  truncation_ = std::move(how);
}

bool McapReader::read_record() {
  record_offset_ = offset_;
  errno = 0;
  const std::size_t got = std::fread(prefix_, 1, sizeof prefix_, file_.get());
  if (got < sizeof prefix_) {
    if (std::ferror(file_.get())) fail_io("read");
    end_truncated(
        got == 0 ? fmt::format(
                       "file ends after the complete record ending at offset {}, without a Footer",
                       offset_)
                 : fmt::format("file ends {} bytes into the 9-byte prefix of a record at offset {}",
                               got, offset_));
    return false;
  }
  const std::uint64_t length = le64(prefix_ + 1);
  const std::uint64_t content_start = offset_ + sizeof prefix_;
  const std::uint64_t available = file_size_ > content_start ? file_size_ - content_start : 0;
  const auto truncated_record = [&](std::uint64_t present) {
    end_truncated(
        fmt::format("file ends {} bytes into the content of a {}-byte {} record at offset {}",
                    present, length, mcap_opcode_name(prefix_[0]), offset_));
  };
  if (length > available) {  // checked before allocating: a cut file ends early, it does not lie
    truncated_record(available);
    return false;
  }
  content_.resize(static_cast<std::size_t>(length));
  const std::size_t content_got = std::fread(content_.data(), 1, content_.size(), file_.get());
  if (content_got < content_.size()) {
    if (std::ferror(file_.get())) fail_io("read");
    truncated_record(content_got);
    return false;
  }

  const std::uint8_t op = prefix_[0];
  if (!data_end_seen_) {
    if (op != opcode::kDataEnd) {
      data_crc_.update(prefix_);
      data_crc_.update(content_);
    }
  } else if (op != opcode::kFooter) {
    summary_crc_.update(prefix_);
    summary_crc_.update(content_);
  }
  offset_ = content_start + length;
  return true;
}

std::optional<McapMessage> McapReader::next() {
  if (state_ == State::failed) throw Error(failure_);
  try {
    while (chunk_next_ < chunk_end_ || state_ == State::reading) {
      if (chunk_next_ < chunk_end_) {
        if (auto message = next_in_chunk()) return message;
        continue;
      }
      if (!read_record()) return std::nullopt;
      if (auto message = dispatch_record()) {
        count(*message, false);
        return message;
      }
    }
  } catch (const Error& e) {
    state_ = State::failed;
    failure_ = e.what();
    throw;
  }
  return std::nullopt;
}

std::optional<McapMessage> McapReader::dispatch_record() {
  try {
    return dispatch(prefix_[0], content_);
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {} record at offset {}: {}", path_.string(),
                            mcap_opcode_name(prefix_[0]), record_offset_, e.what()));
  }
}

void McapReader::open_chunk() {
  ByteCursor cursor(content_);
  const std::uint64_t start_time = cursor.u64("message_start_time");
  const std::uint64_t end_time = cursor.u64("message_end_time");
  const std::uint64_t uncompressed_size = cursor.u64("uncompressed_size");
  const std::uint32_t recorded_crc = cursor.u32("uncompressed_crc");
  const std::string compression = cursor.string("compression");
  const std::uint64_t records_size = cursor.u64("records");
  const std::size_t records_begin = content_.size() - cursor.remaining();
  const auto records = cursor.bytes(
      static_cast<std::size_t>(std::min<std::uint64_t>(records_size, SIZE_MAX)), "records");
  if (!compression.empty()) {
    throw Error(fmt::format("its records are compressed ('{}'): only uncompressed chunks are read",
                            compression));
  }
  if (uncompressed_size != records.size()) {
    throw Error(fmt::format("uncompressed_size is {} but its records take {} bytes",
                            uncompressed_size, records.size()));
  }
  chunk_checked_ = recorded_crc != 0;  // 0: no CRC computed, by the spec
  if (chunk_checked_) {
    const std::uint32_t computed = crc32(records);
    if (computed != recorded_crc) {
      throw Error(fmt::format(
          "the CRC-32 of its records (messages logged from {} to {} ns) is recorded as {:08x} but "
          "computes to {:08x}: the chunk is corrupt",
          start_time, end_time, recorded_crc, computed));
    }
    coverage_.checked_through_offset = offset_;
  }
  chunk_offset_ = record_offset_;
  chunk_next_ = records_begin;
  chunk_end_ = records_begin + records.size();
  std::swap(chunk_, content_);
}

std::optional<McapMessage> McapReader::next_in_chunk() {
  const std::size_t at = chunk_next_;
  const auto fail = [&](const std::string& record, const std::string& what) {
    return Error(fmt::format("{}: {} at offset {} inside the Chunk at offset {}: {}",
                             path_.string(), record, chunk_offset_ + kRecordPrefixBytes + at,
                             chunk_offset_, what));
  };
  const std::size_t available = chunk_end_ - at;
  if (available < kRecordPrefixBytes) {
    throw fail(
        "a record",
        fmt::format("its 9-byte prefix runs past the end of the chunk's records ({} bytes left)",
                    available));
  }
  const std::uint8_t op = chunk_[at];
  const std::uint64_t length = le64(chunk_.data() + at + 1);
  const auto name = [op] { return mcap_opcode_name(op) + " record"; };  // for errors only
  if (length > available - kRecordPrefixBytes) {
    throw fail(
        name(),
        fmt::format(
            "its {} bytes of content run past the end of the chunk's records ({} bytes left)",
            length, available - kRecordPrefixBytes));
  }
  chunk_next_ = at + kRecordPrefixBytes + static_cast<std::size_t>(length);
  if (!belongs_in_chunk(op)) {
    if (defined_by_spec(op))
      throw fail(name(), "only Schema, Channel and Message records belong in a Chunk");
    return std::nullopt;  // a record type of a later version of the spec
  }
  std::optional<McapMessage> message;
  try {
    message = dispatch(
        op, std::span<const std::uint8_t>(chunk_).subspan(at + kRecordPrefixBytes, length));
  } catch (const Error& e) {
    throw fail(name(), e.what());
  }
  if (message) count(*message, chunk_checked_);
  return message;
}

void McapReader::count(const McapMessage& message, bool checked) {
  messages_end_time_ = std::max(messages_end_time_.value_or(0), message.log_time_ns);
  if (!checked) {
    ++coverage_.unchecked_messages;
    return;
  }
  ++coverage_.checked_messages;
  coverage_.checked_end_time_ns =
      std::max(coverage_.checked_end_time_ns.value_or(0), message.log_time_ns);
}

std::optional<McapMessage> McapReader::dispatch(std::uint8_t op,
                                                std::span<const std::uint8_t> content) {
  ByteCursor cursor(content);
  switch (op) {
    case opcode::kHeader: {
      if (header_seen_) throw Error("a second Header record");
      header_seen_ = true;
      profile_ = cursor.string("profile");
      library_ = cursor.string("library");
      return std::nullopt;
    }
    case opcode::kSchema: {
      McapSchema schema;
      schema.id = cursor.u16("id");
      schema.name = cursor.string("name");
      schema.encoding = cursor.string("encoding");
      schema.data = cursor.string("data");
      if (schema.id == 0) return std::nullopt;  // invalid by the spec: ignored
      const auto [it, inserted] = schemas_.try_emplace(schema.id, schema);
      if (!inserted && it->second != schema) {
        throw Error(fmt::format("schema {} ('{}') differs from the earlier schema with that id",
                                schema.id, schema.name));
      }
      return std::nullopt;
    }
    case opcode::kChannel: {
      McapChannel channel;
      channel.id = cursor.u16("id");
      channel.schema_id = cursor.u16("schema_id");
      channel.topic = cursor.string("topic");
      channel.message_encoding = cursor.string("message_encoding");
      channel.metadata = read_string_map(cursor, "metadata");
      if (channel.schema_id != 0 && !schemas_.contains(channel.schema_id)) {
        throw Error(
            fmt::format("channel {} ('{}') refers to schema {}, which no earlier record defines",
                        channel.id, channel.topic, channel.schema_id));
      }
      const auto [it, inserted] = channels_.try_emplace(channel.id, channel);
      if (!inserted && it->second != channel) {
        throw Error(fmt::format("channel {} ('{}') differs from the earlier channel with that id",
                                channel.id, channel.topic));
      }
      return std::nullopt;
    }
    case opcode::kMessage: {
      McapMessage message;
      message.channel_id = cursor.u16("channel_id");
      message.sequence = cursor.u32("sequence");
      message.log_time_ns = cursor.u64("log_time");
      message.publish_time_ns = cursor.u64("publish_time");
      const auto data = cursor.rest();
      message.data.assign(data.begin(), data.end());
      if (!channels_.contains(message.channel_id)) {
        throw Error(fmt::format("message on channel {}, which no earlier Channel record defines",
                                message.channel_id));
      }
      return message;
    }
    case opcode::kChunk:
      open_chunk();
      return std::nullopt;
    case opcode::kDataEnd: {
      const std::uint32_t recorded = cursor.u32("data_section_crc");
      if (recorded != 0 && recorded != data_crc_.value()) {
        throw Error(fmt::format(
            "data section CRC-32 is recorded as {:08x} but computes to {:08x}: the file is "
            "corrupt",
            recorded, data_crc_.value()));
      }
      data_end_seen_ = true;
      summary_begin_ = offset_;
      if (recorded != 0) {  // it covers every message of the data section
        coverage_.checked_messages += coverage_.unchecked_messages;
        coverage_.unchecked_messages = 0;
        coverage_.checked_end_time_ns = messages_end_time_;
        coverage_.checked_through_offset = offset_;
      }
      return std::nullopt;
    }
    case opcode::kStatistics: {
      McapStatistics s;
      s.message_count = cursor.u64("message_count");
      s.schema_count = cursor.u16("schema_count");
      s.channel_count = cursor.u32("channel_count");
      s.attachment_count = cursor.u32("attachment_count");
      s.metadata_count = cursor.u32("metadata_count");
      s.chunk_count = cursor.u32("chunk_count");
      s.message_start_time_ns = cursor.u64("message_start_time");
      s.message_end_time_ns = cursor.u64("message_end_time");
      ByteCursor counts = cursor.prefixed("channel_message_counts");
      while (counts.remaining() > 0) {
        const std::uint16_t channel = counts.u16("channel_message_counts");
        s.channel_message_counts[channel] = counts.u64("channel_message_counts");
      }
      statistics_ = std::move(s);
      return std::nullopt;
    }
    case opcode::kFooter:
      read_footer();
      return std::nullopt;
    default:  // unknown records, and known ones of no use here: skipped
      return std::nullopt;
  }
}

void McapReader::read_footer() {
  ByteCursor cursor(content_);
  const std::uint64_t summary_start = cursor.u64("summary_start");
  cursor.u64("summary_offset_start");
  const std::uint32_t summary_crc = cursor.u32("summary_crc");
  if (data_end_seen_) {
    if (summary_start != 0 && summary_start != summary_begin_) {
      throw Error(
          fmt::format("summary_start {} does not point just past the Data End record (offset {})",
                      summary_start, summary_begin_));
    }
    if (summary_crc != 0) {
      summary_crc_.update(prefix_);
      summary_crc_.update(std::span<const std::uint8_t>(content_).first(16));
      if (summary_crc_.value() != summary_crc) {
        throw Error(fmt::format(
            "summary CRC-32 is recorded as {:08x} but computes to {:08x}: the file is corrupt",
            summary_crc, summary_crc_.value()));
      }
    }
  }

  std::uint8_t magic[8] = {};
  errno = 0;
  const std::size_t got = std::fread(magic, 1, sizeof magic, file_.get());
  if (got < sizeof magic) {
    if (std::ferror(file_.get())) fail_io("read");
    end_truncated(fmt::format("file ends after {} of the 8 bytes of the closing magic", got));
    return;
  }
  if (!std::equal(magic, magic + sizeof magic, kMcapMagic.begin()))
    throw Error("no closing magic after the Footer");
  if (std::fgetc(file_.get()) != EOF) throw Error("bytes follow the closing magic");
  if (std::ferror(file_.get())) fail_io("read");
  offset_ += sizeof magic;
  complete_ = true;
  state_ = State::ended;
}

const McapChannel& McapReader::channel_of(const McapMessage& message) const {
  const auto it = channels_.find(message.channel_id);
  if (it == channels_.end()) {
    throw Error(fmt::format("{}: no channel {} in this file", path_.string(), message.channel_id));
  }
  return it->second;
}

const McapSchema* McapReader::schema_of(const McapMessage& message) const {
  const auto it = schemas_.find(channel_of(message).schema_id);
  return it == schemas_.end() ? nullptr : &it->second;
}

bool McapReader::carries_protobuf(const McapMessage& message, std::string_view full_name) const {
  const auto channel = channels_.find(message.channel_id);
  if (channel == channels_.end() || channel->second.message_encoding != "protobuf") return false;
  const auto schema = schemas_.find(channel->second.schema_id);
  return schema != schemas_.end() && schema->second.encoding == "protobuf" &&
         schema->second.name == full_name;
}

}  // namespace cohaptic::record
