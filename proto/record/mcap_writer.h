// McapWriter records timestamped messages (protobuf, normally) into an MCAP file
// (https://mcap.dev/spec) that survives the death of the writing process and checks
// itself even when cut short.
//
// Layout: magic, Header (profile "", library "cohaptic"), then the data section: every
// flush writes the Schema, Channel and Message records buffered since the last one as one
// uncompressed Chunk record whose uncompressed_crc is the CRC-32 of those records, followed
// by one Message Index record per channel with messages in it. A writer killed mid-session
// thus leaves complete, self-checking chunks up to its last flush: McapReader checks each
// chunk's CRC before it yields a message from it, so a damaged byte in a cut file is found
// without the Data End CRC that only close() writes. (The Header, before any chunk as the
// spec requires, and the Message Index records are covered by the Data End CRC only.)
// close() ends the file as the spec describes: Data End (with the data section's CRC-32),
// the summary section (Schema, Channel, Statistics and one Chunk Index per chunk, grouped
// by opcode), one Summary Offset record per group, the Footer (pointing at both, with the
// summary CRC-32) and the closing magic, so that indexed readers (Foxglove, Lichtblick,
// @mcap/core) open it in full and find each message through the indexes.
//
// Flushing: records collect in a memory buffer and reach the file as one chunk (one
// fwrite + fflush, i.e. the operating system, not necessarily the disk platter) on flush(),
// when the chunk and its indexes would take `flush_bytes` or more, and when a write() or
// flush_if_due() finds that `flush_interval` has passed since the last flush. An owner that
// may stay silent for long should call flush_if_due() from its loop. The constructor writes
// the Header at once, so a file that cannot be written fails there.
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
  /// ... and as soon as the buffered chunk (with its Message Index records) takes this
  /// many bytes.
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

  /// Buffers a Schema record for the next chunk; returns its id (1, 2, ...). `data` is in
  /// `encoding`'s format.
  std::uint16_t add_schema(std::string_view name, std::string_view encoding, std::string_view data);
  /// add_schema(schema_name(d), "protobuf", protobuf_schema_data(d)).
  std::uint16_t add_protobuf_schema(const google::protobuf::Descriptor* descriptor);
  /// Buffers a Channel record for the next chunk; returns its id (1, 2, ...). schema_id 0
  /// means "no schema"; any other must have been returned by add_schema.
  std::uint16_t add_channel(std::uint16_t schema_id, std::string_view topic,
                            std::string_view message_encoding = "protobuf",
                            const std::map<std::string, std::string>& metadata = {});

  /// Buffers a Message record on `channel_id` (returned by add_channel) for the next chunk.
  void write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
             std::uint64_t publish_time_ns, std::span<const std::uint8_t> data);
  /// Serializes `message` and writes it as above.
  void write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
             std::uint64_t publish_time_ns, const google::protobuf::MessageLite& message);

  /// Hands every buffered record to the operating system now, as one chunk (none if
  /// nothing is buffered).
  void flush();
  /// flush() if flush_interval has passed since the last flush and records are buffered.
  void flush_if_due();
  /// Writes Data End, the summary, the Footer and the closing magic, and closes the file.
  /// Calling it again does nothing.
  void close();

  bool is_closed() const { return state_ == State::closed; }
  const std::filesystem::path& path() const { return path_; }
  std::uint64_t message_count() const { return message_count_; }
  /// Bytes of the file so far: flushed, plus what a flush would write now.
  std::uint64_t size() const { return offset_ + buffered_bytes(); }

 private:
  enum class State { open, closed, failed };
  /// A message's place in the chunk being filled, for its channel's Message Index record.
  struct IndexEntry {
    std::uint64_t log_time_ns;
    std::uint64_t offset;  ///< from the start of the chunk's records
  };

  void check_usable() const;
  /// Appends a complete Schema or Channel record to the chunk being filled.
  void append(std::span<const std::uint8_t> record);
  /// Reserves the chunk's head in chunk_ if it holds no record yet.
  void start_chunk();
  std::uint64_t buffered_bytes() const;
  void maybe_flush();
  /// Completes the chunk being filled (its head, its Message Index records), writes it and
  /// keeps its Chunk Index record for the summary.
  void write_chunk();
  /// Writes `bytes` to the file now, feeding the data-section CRC if `in_data_section`.
  void write_now(std::span<const std::uint8_t> bytes, bool in_data_section);
  [[noreturn]] void fail(std::string_view operation);

  struct FileCloser {
    void operator()(std::FILE* file) const;
  };

  std::filesystem::path path_;
  McapWriterOptions options_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  State state_ = State::open;
  std::string failure_;

  /// The chunk being filled: empty, or its head (kRecordPrefixBytes + kChunkFieldsBytes,
  /// filled in by write_chunk) followed by its records.
  std::vector<std::uint8_t> chunk_;
  std::vector<std::vector<IndexEntry>>
      chunk_entries_;                          ///< by channel id - 1, this chunk's messages
  std::vector<std::uint16_t> chunk_channels_;  ///< channels with messages in this chunk
  std::uint64_t chunk_message_count_ = 0;
  std::uint64_t chunk_start_time_ = 0;
  std::uint64_t chunk_end_time_ = 0;
  std::uint64_t index_bytes_ = 0;      ///< the Message Index records this chunk will need
  std::vector<std::uint8_t> scratch_;  ///< reused for serializing
  std::uint64_t offset_ = 0;           ///< bytes handed to the file so far
  std::chrono::steady_clock::time_point last_flush_;
  Crc32 data_crc_;

  std::vector<std::vector<std::uint8_t>> schema_records_;   ///< by id - 1, repeated in the summary
  std::vector<std::vector<std::uint8_t>> channel_records_;  ///< by id - 1, repeated in the summary
  std::vector<std::uint8_t> chunk_indexes_;  ///< one Chunk Index record per chunk written
  std::uint32_t chunk_count_ = 0;
  std::vector<std::uint64_t> channel_message_counts_;  ///< by id - 1
  std::uint64_t message_count_ = 0;
  std::uint64_t message_start_time_ = 0;
  std::uint64_t message_end_time_ = 0;
};

}  // namespace cohaptic::record
