#include "proto/wire/ir_stream.h"

#include <fmt/format.h>
#include <zstd.h>

#include <algorithm>
#include <string>

#include "common/util/error.h"

namespace cohaptic::wire {
namespace {

constexpr int kIrStreamLevel = 1;  // zstd's fastest: long-distance matching finds the repeats

void check_zstd(std::size_t code, const char* what) {
  if (ZSTD_isError(code))
    throw cohaptic::Error(fmt::format("IR stream: {}: {}", what, ZSTD_getErrorName(code)));
}

}  // namespace

struct IrStreamWriter::Context {
  ZSTD_CCtx* cctx = ZSTD_createCCtx();
  ~Context() { ZSTD_freeCCtx(cctx); }
};

struct IrStreamReader::Context {
  ZSTD_DCtx* dctx = ZSTD_createDCtx();
  ~Context() { ZSTD_freeDCtx(dctx); }
};

IrStreamWriter::IrStreamWriter() : context_(std::make_unique<Context>()) {
  if (!context_->cctx)
    throw cohaptic::Error("IR stream: zstd could not make a compression context");
}
IrStreamWriter::~IrStreamWriter() = default;
IrStreamWriter::IrStreamWriter(IrStreamWriter&&) noexcept = default;
IrStreamWriter& IrStreamWriter::operator=(IrStreamWriter&&) noexcept = default;

CompressedIr IrStreamWriter::compress(const IntermediateRepresentation& ir, bool fresh) {
  ZSTD_CCtx* cctx = context_->cctx;
  if (fresh || index_ == 0) {
    check_zstd(ZSTD_CCtx_reset(cctx, ZSTD_reset_session_and_parameters), "reset");
    check_zstd(ZSTD_CCtx_setParameter(cctx, ZSTD_c_compressionLevel, kIrStreamLevel), "level");
    check_zstd(ZSTD_CCtx_setParameter(cctx, ZSTD_c_windowLog, kIrStreamWindowLog), "window");
    check_zstd(ZSTD_CCtx_setParameter(cctx, ZSTD_c_enableLongDistanceMatching, 1), "ldm");
    index_ = 0;
  }
  const std::string serialized = ir.SerializeAsString();
  std::string out(ZSTD_compressBound(serialized.size()) + 64, '\0');
  ZSTD_inBuffer input{serialized.data(), serialized.size(), 0};
  ZSTD_outBuffer output{out.data(), out.size(), 0};
  // Flush: the block decodes on its own given the blocks before it; the stream never ends.
  for (;;) {
    const std::size_t remaining = ZSTD_compressStream2(cctx, &output, &input, ZSTD_e_flush);
    check_zstd(remaining, "compress");
    if (remaining == 0) break;
    if (output.pos == output.size) {
      out.resize(out.size() * 2);
      output = {out.data(), out.size(), output.pos};
    }
  }
  out.resize(output.pos);
  CompressedIr block;
  block.set_index(++index_);
  block.set_zstd(std::move(out));
  return block;
}

IrStreamReader::IrStreamReader() : context_(std::make_unique<Context>()) {
  if (!context_->dctx)
    throw cohaptic::Error("IR stream: zstd could not make a decompression context");
}
IrStreamReader::~IrStreamReader() = default;
IrStreamReader::IrStreamReader(IrStreamReader&&) noexcept = default;
IrStreamReader& IrStreamReader::operator=(IrStreamReader&&) noexcept = default;

IntermediateRepresentation IrStreamReader::open(const CompressedIr& block) {
  ZSTD_DCtx* dctx = context_->dctx;
  if (block.index() == 1) {
    check_zstd(ZSTD_DCtx_reset(dctx, ZSTD_reset_session_and_parameters), "reset");
    check_zstd(ZSTD_DCtx_setParameter(dctx, ZSTD_d_windowLogMax, kIrStreamWindowLog), "window");
  } else if (index_ == 0 || block.index() != index_ + 1) {
    const std::uint64_t held = index_;
    index_ = 0;
    throw cohaptic::Error(
        fmt::format("a compressed IR block {} of its stream, and this client opened block {} last: "
                    "refused, until the server starts the stream afresh",
                    block.index(), held));
  }
  index_ = 0;  // until this block is opened whole
  const std::string& zstd = block.zstd();
  // The buffer is kept from block to block: it grows to the largest IR once, instead of a
  // block of several times the frame's size being allocated and zeroed for every IR.
  std::string& out = buffer_;
  const std::size_t first_guess =
      std::min(kMaxStreamIrBytes, std::max<std::size_t>(4096, 4 * zstd.size()));
  if (out.size() < first_guess) out.resize(first_guess);
  ZSTD_inBuffer input{zstd.data(), zstd.size(), 0};
  ZSTD_outBuffer output{out.data(), out.size(), 0};
  // A flushed block is whole once its input is consumed and the output was not filled.
  while (input.pos < input.size || output.pos == output.size) {
    if (output.pos == output.size) {
      if (out.size() >= kMaxStreamIrBytes)
        throw cohaptic::Error(
            fmt::format("compressed IR block {} decompresses to more than {} bytes: refused",
                        block.index(), kMaxStreamIrBytes));
      out.resize(std::min(kMaxStreamIrBytes, 2 * out.size()));
      output = {out.data(), out.size(), output.pos};
    }
    const std::size_t code = ZSTD_decompressStream(dctx, &output, &input);
    if (ZSTD_isError(code))
      throw cohaptic::Error(fmt::format("compressed IR block {}: zstd cannot decompress it: {}",
                                        block.index(), ZSTD_getErrorName(code)));
    if (input.pos == input.size && output.pos < output.size) break;
  }
  IntermediateRepresentation ir;
  if (!ir.ParseFromArray(out.data(), static_cast<int>(output.pos)))
    throw cohaptic::Error(fmt::format("compressed IR block {}: its {} bytes are not an IR",
                                      block.index(), output.pos));
  index_ = block.index();
  return ir;
}

}  // namespace cohaptic::wire
