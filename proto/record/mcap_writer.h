// McapWriter records timestamped messages (protobuf, normally) into an MCAP file
// (https://mcap.dev/spec) that survives the death of the writing process.
//
// Layout: magic, Header (profile "", library "cohaptic"), then the data section with
// Schema, Channel and Message records written directly, never inside Chunks: every record
// is complete on disk once flushed, so a writer killed mid-session leaves a file that
// McapReader (and any streaming MCAP reader) reads up to its last complete record.
// close() ends the file as the spec describes: Data End (with the data section's CRC-32),
// the summary section (Schema, Channel and Statistics records, grouped by opcode), one
// Summary Offset record per group, the Footer (pointing at both, with the summary CRC-32)
// and the closing magic, so that indexed readers (Foxglove, Lichtblick, @mcap/core) open
// it in full. Without chunks nothing indexes the messages themselves; readers that need
// them scan the data section (what Foxglove and Lichtblick do for unchunked files).
//
// Flushing: records collect in a memory buffer and reach the file (fwrite + fflush, i.e.
// the operating system, not necessarily the disk platter) on flush(), when the buffer
// holds `flush_bytes` or more, and when a write() or flush_if_due() finds that
// `flush_interval` has passed since the last flush. An owner that may stay silent for
// long should call flush_if_due() from its loop. The constructor flushes the Header, so a
// file that cannot be written fails there.
//
// Errors: a file that cannot be opened or written (full disk, quota, I/O error) throws
// cohaptic::Error naming the file and the reason (strerror); nothing is dropped silently.
// After such an error the writer is unusable: every later call throws again, and the
// destructor only closes the descriptor. Arguments that are wrong (an unknown channel or
// schema id, too many channels) throw without writing anything and leave the writer usable.
//
// Units: times are u64 nanoseconds since an epoch the caller chooses (the recording's
// clock); sizes are bytes. Ids: schema and channel ids count from 1 in the order added.
//
// Thread-safety: none. One thread owns the writer; others hand it their messages (e.g.
// through a queue).
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "proto/record/crc32.h"

namespace google::protobuf {
class Descriptor;
class MessageLite;
}  // namespace google::protobuf

namespace cohaptic::record {

struct McapWriterOptions {
  /// Buffered records reach the file at least this often (checked on write/flush_if_due).
  std::chrono::milliseconds flush_interval{100};
  /// ... and as soon as this many bytes are buffered.
  std::size_t flush_bytes = std::size_t{1} << 20;
};

class McapWriter {
 public:
  /// Creates (or truncates) `path` and writes the magic and the Header, flushed.
  /// Throws cohaptic::Error naming the path and the reason if that fails.
  explicit McapWriter(std::filesystem::path path, McapWriterOptions options = {});
  /// Closes the file as close() does if it is still open; an error there is logged, not thrown.
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// Writes a Schema record; returns its id (1, 2, ...). `data` is in `encoding`'s format.
  std::uint16_t add_schema(std::string_view name, std::string_view encoding, std::string_view data);
  /// add_schema(schema_name(d), "protobuf", protobuf_schema_data(d)).
  std::uint16_t add_protobuf_schema(const google::protobuf::Descriptor* descriptor);
  /// Writes a Channel record; returns its id (1, 2, ...). schema_id 0 means "no schema";
  /// any other must have been returned by add_schema.
  std::uint16_t add_channel(std::uint16_t schema_id, std::string_view topic,
                            std::string_view message_encoding = "protobuf",
                            const std::map<std::string, std::string>& metadata = {});

  /// Writes a Message record on `channel_id` (returned by add_channel).
  void write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
             std::uint64_t publish_time_ns, std::span<const std::uint8_t> data);
  /// Serializes `message` and writes it as above.
  void write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
             std::uint64_t publish_time_ns, const google::protobuf::MessageLite& message);

  /// Hands every buffered record to the operating system now.
  void flush();
  /// flush() if flush_interval has passed since the last flush and records are buffered.
  void flush_if_due();
  /// Writes Data End, the summary, the Footer and the closing magic, and closes the file.
  /// Calling it again does nothing.
  void close();

  bool is_closed() const { return state_ == State::closed; }
  const std::filesystem::path& path() const { return path_; }
  std::uint64_t message_count() const { return message_count_; }
  /// Bytes of the file so far, flushed or still buffered.
  std::uint64_t size() const { return offset_ + pending_.size(); }

 private:
  enum class State { open, closed, failed };

  void check_usable() const;
  /// Appends a complete record to the buffer, feeding the data-section CRC.
  void append(std::span<const std::uint8_t> record);
  void maybe_flush();
  /// Writes `bytes` to the file now (bypassing the buffer, which must be empty).
  void write_now(std::span<const std::uint8_t> bytes);
  [[noreturn]] void fail(std::string_view operation);

  struct FileCloser {
    void operator()(std::FILE* file) const;
  };

  std::filesystem::path path_;
  McapWriterOptions options_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  State state_ = State::open;
  std::string failure_;

  std::vector<std::uint8_t> pending_;  ///< records not yet handed to the file
  std::vector<std::uint8_t> scratch_;  ///< reused for building records and serializing
  std::uint64_t offset_ = 0;           ///< bytes handed to the file so far
  std::chrono::steady_clock::time_point last_flush_;
  Crc32 data_crc_;

  std::vector<std::vector<std::uint8_t>> schema_records_;   ///< by id - 1, repeated in the summary
  std::vector<std::vector<std::uint8_t>> channel_records_;  ///< by id - 1, repeated in the summary
  std::vector<std::uint64_t> channel_message_counts_;       ///< by id - 1
  std::uint64_t message_count_ = 0;
  std::uint64_t message_start_time_ = 0;
  std::uint64_t message_end_time_ = 0;
};

}  // namespace cohaptic::record
