// The vocabulary of the MCAP container format (https://mcap.dev/spec), major version 0:
// the magic that opens and closes a file, the record opcodes, and the fixed sizes of the
// records cohaptic writes. Every record on disk is
//   [u8 opcode][u64 content length][content]
// with all integers little-endian; strings and byte strings carry a u32 length prefix.
// Timestamps are u64 nanoseconds since an epoch the recording chooses.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace cohaptic::record {

/// 0x89 "MCAP" '0' "\r\n": the first and last 8 bytes of every MCAP file.
inline constexpr std::array<std::uint8_t, 8> kMcapMagic = {0x89, 'M', 'C',  'A',
                                                           'P',  '0', '\r', '\n'};

namespace opcode {
inline constexpr std::uint8_t kHeader = 0x01;
inline constexpr std::uint8_t kFooter = 0x02;
inline constexpr std::uint8_t kSchema = 0x03;
inline constexpr std::uint8_t kChannel = 0x04;
inline constexpr std::uint8_t kMessage = 0x05;
inline constexpr std::uint8_t kChunk = 0x06;
inline constexpr std::uint8_t kMessageIndex = 0x07;
inline constexpr std::uint8_t kChunkIndex = 0x08;
inline constexpr std::uint8_t kAttachment = 0x09;
inline constexpr std::uint8_t kAttachmentIndex = 0x0A;
inline constexpr std::uint8_t kStatistics = 0x0B;
inline constexpr std::uint8_t kMetadata = 0x0C;
inline constexpr std::uint8_t kMetadataIndex = 0x0D;
inline constexpr std::uint8_t kSummaryOffset = 0x0E;
inline constexpr std::uint8_t kDataEnd = 0x0F;
}  // namespace opcode

/// Opcode byte + u64 content length.
inline constexpr std::size_t kRecordPrefixBytes = 9;
/// Message content before its data: channel id (2), sequence (4), log and publish time (8 + 8).
inline constexpr std::size_t kMessageFixedBytes = 22;
/// Footer content: summary_start (8), summary_offset_start (8), summary_crc (4).
inline constexpr std::size_t kFooterContentBytes = 20;
/// DataEnd content: data_section_crc (4).
inline constexpr std::size_t kDataEndContentBytes = 4;
/// Chunk content before its records when its compression is "" (none): message start and
/// end time (8 + 8), uncompressed_size (8), uncompressed_crc (4), compression (4 + 0) and
/// the records' u64 length (8).
inline constexpr std::size_t kChunkFieldsBytes = 40;
/// One entry of a Message Index record: a message's log time (8) and its offset (8).
inline constexpr std::size_t kMessageIndexEntryBytes = 16;

/// The record's name in the spec ("Message", "Chunk", ...), or "unknown (0xNN)".
std::string mcap_opcode_name(std::uint8_t opcode);

}  // namespace cohaptic::record
