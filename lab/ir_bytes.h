// `cohaptic-lab ir-bytes RECORDING...`: what a client's condensed FEM IRs cost on the wire,
// and what three ways of sending less would have cost, on the IRs a client recorded
// (cohaptic-client --record). Per recording, over its IRs in arrival order:
//   - sent: the wire IRs as received (bytes and kB/s over the span from first to last IR),
//     and of that everything but M~ (geometry, node ids, u_B);
//   - f32: the same IRs with M~ and u_B rounded to float;
//   - M~ delta: each IR with only the entries of M~ that differ from the previous IR's
//     (value + index, 12 bytes each) when the local nodes are the same, else the whole M~;
//   - compliance rows: instead of M~, the rows of the compliance block L_AA (A: every local
//     node, 3 dofs each, symmetric) of nodes the previous IR did not have; the client would
//     keep L_AA and condense it itself (M~ = the C rows of L_AA^-1). Its CPU per IR is timed
//     here as a dense Cholesky of the IR's 3|A| x 3|A| block and the solve for its C rows,
//     on a synthetic symmetric positive definite matrix of that size (the cost depends on
//     the size only).
// `--frames DIR` also writes every IR as sent, one file each (frame_NNNNNN.bin), to measure a
// general-purpose compressor on them (e.g. zstd). Units: bytes, kB = 1000 bytes, s, µs.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "lab/lab_command.h"

namespace cohaptic {

struct IrBytesRow {
  std::string recording;
  std::size_t irs = 0;
  double span_s = 0;          ///< first IR to last
  double nodes_mean = 0;      ///< local nodes |A| per IR
  double new_nodes_mean = 0;  ///< nodes per IR the previous IR did not have
  double sent_bytes = 0, f32_bytes = 0, delta_bytes = 0, rows_bytes = 0;  ///< totals
  double without_m_bytes = 0;  ///< everything but M~: what no way of sending M~ can save
  double rows_client_us_p50 = 0, rows_client_us_max = 0;  ///< condensing L_AA per IR
};

/// Measures one recording (throws Error naming it if it holds no condensed FEM IR).
/// `frames`: if not empty, a directory to write the IRs as sent into.
IrBytesRow measure_ir_bytes(const std::filesystem::path& recording, const std::filesystem::path& frames);

/// `cohaptic-lab ir-bytes RECORDING... [--frames DIR]`: a Markdown table on stdout.
LabCommand add_ir_bytes_command(CLI::App& lab);

}  // namespace cohaptic
