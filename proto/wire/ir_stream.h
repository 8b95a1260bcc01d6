// IR streams: the compliance rows IRs (common/ir/compliance_rows.h), or the sphere contact
// model's IRs, of one user's connection, compressed as one zstd stream, each IR a flushed
// block of it. They already travel must-arrive and in order over TCP, and consecutive IRs
// repeat most of each other (node ids, patch geometry, the held nodes' displacements, the
// normal compliance between rows both hold), so the stream costs a small part of the IRs'
// bytes where each IR alone would keep about two thirds (`cohaptic-lab ir-bytes` measures
// it). A sphere IR's repeats lie hundreds of kB back: long-distance matching finds them.
//
// The stream starts afresh where the rows do (generation 1): the writer resets and the IR
// is index 1; the reader resets on index 1 and opens index k + 1 only after k, so a reader
// that missed a block (a new user of the slot, reached by an IR built for the one before)
// refuses everything until the next fresh start instead of decoding garbage.
// Memory: the writer's window is 2^21 bytes, the reader refuses larger ones; an IR
// decompresses to at most kMaxStreamIrBytes. Not thread-safe (one per connection).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "cohaptic/messages.pb.h"

namespace cohaptic::wire {

constexpr std::size_t kMaxStreamIrBytes = std::size_t{64}
                                          << 20;  ///< the frame body limit, frame_codec.h
constexpr int kIrStreamWindowLog = 21;

class IrStreamWriter {
 public:
  IrStreamWriter();
  ~IrStreamWriter();
  IrStreamWriter(IrStreamWriter&&) noexcept;
  IrStreamWriter& operator=(IrStreamWriter&&) noexcept;

  /// `ir` as the next block of the stream; `fresh`: start a new stream with it (index 1).
  /// Throws cohaptic::Error if zstd fails.
  CompressedIr compress(const IntermediateRepresentation& ir, bool fresh);

 private:
  struct Context;
  std::unique_ptr<Context> context_;
  std::uint64_t index_ = 0;
};

class IrStreamReader {
 public:
  IrStreamReader();
  ~IrStreamReader();
  IrStreamReader(IrStreamReader&&) noexcept;
  IrStreamReader& operator=(IrStreamReader&&) noexcept;

  /// The IR of the next block. Throws cohaptic::Error, saying why, for a block that does not
  /// follow the last one opened (and then refuses all but a fresh start), that zstd cannot
  /// decompress, that decompresses to more than kMaxStreamIrBytes, or that is not an IR.
  IntermediateRepresentation open(const CompressedIr& block);

 private:
  struct Context;
  std::unique_ptr<Context> context_;
  std::uint64_t index_ = 0;  ///< the last block opened; 0: none, only a fresh start is accepted
  std::string buffer_;       ///< where blocks decompress, kept at the largest IR's size (at most
                             ///< kMaxStreamIrBytes)
};

}  // namespace cohaptic::wire
