// McapReader reads an MCAP file (https://mcap.dev/spec) from the front, record after
// record, as a streaming reader does: it needs no summary or footer, so it reads what a
// crashed writer left behind. Schemas and channels are collected as they are met (the
// maps grow while next() advances); next() returns the messages in file order. It reads
// chunked files (McapWriter's) and unchunked ones alike; the indexes (Message Index, Chunk
// Index) are not needed for that and are skipped.
//
// CRCs: a Chunk's records are checked against its uncompressed_crc before any message in it
// is returned, so a damaged chunk yields nothing; the data-section CRC (Data End) and the
// summary CRC (Footer) are checked when reached, after the messages they cover were
// returned. crc_coverage() says which of the messages returned so far a checked CRC covers.
// In a file cut short only its complete chunks are covered: the messages of an unchunked
// file cut short are covered by no CRC at all, and a chunk whose opcode byte or length is
// damaged reads as an unknown record (skipped), as extra bytes or as the place the file was
// cut: its messages are missing, never wrong.
//
// Truncation is not an error: a file that ends inside a record (a Chunk, say), or after a
// complete record but before the Footer, yields every message of its complete records (of
// its complete chunks, in a chunked file); once next() has returned nullopt, truncated() is
// true and truncation() says where and how the file ends (valid_bytes() is the length of its
// readable prefix). A file shorter than the magic whose bytes are a prefix of the magic (an
// empty file, for one) counts as truncated too.
//
// Errors (cohaptic::Error naming the file, and a record by its offset): a file that cannot be
// opened or read; one that does not start with the MCAP magic; a major version other than
// 0; a malformed record (fields running past its declared length, a message on a channel
// never declared, two different records under one id, a second Header, bytes after the
// closing magic, a record inside a Chunk other than Schema, Channel and Message); a Chunk
// whose CRC does not match (the error also gives its messages' log time range) or that is
// compressed (McapWriter never compresses); a wrong data-section or summary CRC. Record
// types it does not know, and known ones it has no use for (attachments, metadata,
// indexes), are skipped, as the spec requires. After an error the reader is unusable:
// next() throws it again.
//
// Units: times are u64 nanoseconds as recorded; offsets and sizes are bytes.
// Thread-safety: none; one thread owns a reader.
#pragma once

#include <climits>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "proto/record/crc32.h"
#include "proto/record/mcap_records.h"

namespace cohaptic::record {

class McapReader {
 public:
  /// Opens `path` and reads the magic and the Header record.
  explicit McapReader(std::filesystem::path path);
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  /// The next message, or nullopt at the end of the file (or of its readable prefix).
  std::optional<McapMessage> next();

  /// Channels and schemas met so far, by id.
  const std::map<std::uint16_t, McapChannel>& channels() const { return channels_; }
  const std::map<std::uint16_t, McapSchema>& schemas() const { return schemas_; }
  /// The summary's Statistics record, once read (complete files only, in practice).
  const std::optional<McapStatistics>& statistics() const { return statistics_; }
  const std::string& profile() const { return profile_; }
  const std::string& library() const { return library_; }
  const std::filesystem::path& path() const { return path_; }

  /// The file ended before its Footer and closing magic (known once next() returned nullopt).
  bool truncated() const { return truncated_; }
  /// The Footer and the closing magic were read.
  bool complete() const { return complete_; }
  /// How the file ends when truncated(), e.g. "file ends 12 bytes into a 57-byte Message
  /// record at offset 4711"; empty otherwise.
  const std::string& truncation() const { return truncation_; }
  /// Bytes of the file read as complete records (with the magic); all of it when complete().
  std::uint64_t valid_bytes() const { return offset_; }
  /// The file's size when it was opened.
  std::uint64_t file_size() const { return file_size_; }
  /// Which of the messages returned so far a checked CRC covers (final once next() returned
  /// nullopt).
  const McapCrcCoverage& crc_coverage() const { return coverage_; }

  /// The channel and the schema of `message` (nullptr if it has none).
  const McapChannel& channel_of(const McapMessage& message) const;
  const McapSchema* schema_of(const McapMessage& message) const;

  /// `message` decoded as ProtoMessage, or nullopt if its channel is not protobuf-encoded
  /// with ProtoMessage's schema (by full name) or its bytes do not parse.
  template <typename ProtoMessage>
  std::optional<ProtoMessage> parse(const McapMessage& message) const {
    if (!carries_protobuf(message, ProtoMessage::default_instance().GetTypeName()))
      return std::nullopt;
    if (message.data.size() > static_cast<std::size_t>(INT_MAX)) return std::nullopt;
    ProtoMessage out;
    if (!out.ParseFromArray(message.data.data(), static_cast<int>(message.data.size())))
      return std::nullopt;
    return out;
  }

 private:
  enum class State { reading, ended, failed };
  struct FileCloser {
    void operator()(std::FILE* file) const;
  };

  bool carries_protobuf(const McapMessage& message, std::string_view full_name) const;
  void read_magic();
  /// Reads the next record into prefix_/content_; false (and the reader ended, truncated)
  /// if the file ends before the record is complete.
  bool read_record();
  /// Acts on the record in prefix_/content_, naming it in any error.
  std::optional<McapMessage> dispatch_record();
  /// Acts on one record; a message is returned, everything else absorbed.
  std::optional<McapMessage> dispatch(std::uint8_t op, std::span<const std::uint8_t> content);
  /// Takes the Chunk record in content_ as the chunk being read, once its CRC matches.
  void open_chunk();
  /// Acts on the next record of the chunk being read, naming it in any error.
  std::optional<McapMessage> next_in_chunk();
  /// Counts a message returned in crc_coverage().
  void count(const McapMessage& message, bool checked);
  void read_footer();
  void end_truncated(std::string how);
  [[noreturn]] void fail_io(const char* operation);

  std::filesystem::path path_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  std::uint64_t file_size_ = 0;
  std::uint64_t offset_ = 0;         ///< end of the last complete record
  std::uint64_t record_offset_ = 0;  ///< start of the record in prefix_/content_
  State state_ = State::reading;
  std::string failure_;
  bool truncated_ = false;
  bool complete_ = false;
  std::string truncation_;

  std::uint8_t prefix_[9] = {};
  std::vector<std::uint8_t> content_;
  /// The Chunk being read: its content, and the range of its records not read yet.
  std::vector<std::uint8_t> chunk_;
  std::size_t chunk_next_ = 0;
  std::size_t chunk_end_ = 0;
  std::uint64_t chunk_offset_ = 0;  ///< of the Chunk record in the file
  bool chunk_checked_ = false;      ///< its CRC matched (a recorded 0 is none)
  McapCrcCoverage coverage_;
  std::optional<std::uint64_t>
      messages_end_time_;  ///< the latest log time of every message returned
  bool header_seen_ = false;
  bool data_end_seen_ = false;
  std::uint64_t summary_begin_ = 0;  ///< offset just past Data End
  Crc32 data_crc_;                   ///< over everything before Data End
  Crc32 summary_crc_;                ///< over everything after Data End, before the Footer

  std::string profile_;
  std::string library_;
  std::map<std::uint16_t, McapSchema> schemas_;
  std::map<std::uint16_t, McapChannel> channels_;
  std::optional<McapStatistics> statistics_;
};

}  // namespace cohaptic::record
