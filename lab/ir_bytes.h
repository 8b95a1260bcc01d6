// `cohaptic-lab ir-bytes RECORDING...`: what a client's condensed FEM IRs cost on the wire,
// and what three ways of sending less would have cost, on the IRs a client recorded
// (cohaptic-client --record). Per recording, over its IRs in arrival order:
//   - sent: the wire IRs as received, out of the connection's stream if they came compressed
//     (bytes and kB/s over the span from first to last IR),
//     and of the whole-M~ form everything but M~ (geometry, node ids, u_B). An IR that came
//     as compliance rows (the server's default) is first completed as the
//     client did (ClientCondensation); every option below is measured on that whole form;
//   - f32: the same IRs with M~ and u_B rounded to float;
//   - M~ delta: each IR with only the entries of M~ that differ from the previous IR's
//     (value + index, 12 bytes each) when the local nodes are the same, else the whole M~;
//   - compliance rows: instead of M~, the rows of the compliance block L_AA (A: every local
//     node, 3 dofs each, symmetric) of nodes the previous IR did not have; the client would
//     keep L_AA and condense it itself. That client work is done here, per IR, on the
//     scene's own compliance by the naive condensation (L_AA over the IR's free dofs, a
//     dense Cholesky, M~ = its inverse's C rows): timed (µs of the thread's CPU per IR, an
//     upper bound for an incremental client) and compared with the M~ the server sent
//     (largest entry difference relative to the largest entry: 0 up to rounding if this way
//     of sending gives the same forces);
//   - as sent: for IRs that came as compliance rows, the CPU of completing them as the
//     client does (ClientCondensation, incremental): p50, max and the first IR's;
//   - zstd stream: the IRs as recorded (rows IRs as they came out of the connection's
//     stream) put through a new IR stream (proto/wire/ir_stream.h) as the server does, its
//     bytes, and the client's CPU to take each out of it (p50 / max).
// `--frames DIR` also writes every IR as sent, one file each (frame_NNNNNN.bin), to measure a
// general-purpose compressor on them (e.g. zstd).
// A recording of sphere IRs (the sphere contact model, which carries the normal compliance W
// of its row nodes instead of M~) gets a table of its own: the IRs as they travelled (whole,
// in the connection's zstd stream) and uncompressed, beside what M~'s forms would send for
// the same IRs, uncompressed: M~ whole (3 rows per row node, a column per free dof of the
// row and held nodes, f64) and compliance rows (the rows of L_AA of the nodes new to the
// client, each pair once, f64). Units: bytes, kB = 1000 bytes, s, µs.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "common/fem/compliance.h"
#include "common/model/elastic_body.h"
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
  double rows_m_tilde_difference =
      0;  ///< largest over the IRs, relative to each IR's largest |M~| entry
  /// IRs that came as compliance rows: the client's own completion (ClientCondensation,
  /// incremental), µs of CPU per IR; 0 when M~ came whole.
  double sent_rows_us_p50 = 0, sent_rows_us_max = 0, sent_rows_first_us = 0;
  double stream_bytes = 0;  ///< the IRs as recorded, through one IR stream (ir_stream.h)
  double stream_inflate_us_p50 = 0,
         stream_inflate_us_max = 0;  ///< the client's CPU per IR to decompress
};

/// Measures one recording (throws Error naming it if it holds no condensed FEM IR, or one
/// whose nodes `body` does not have). `body` and `columns`: the recorded session's body and
/// its compliance (rows for every surface node). `frames`: if not empty, a directory to write
/// the IRs as sent into.
IrBytesRow measure_ir_bytes(const std::filesystem::path& recording, const ElasticBody& body,
                            ComplianceColumns& columns, const std::filesystem::path& frames);

/// A recording of sphere IRs, measured as above.
struct SphereIrBytesRow {
  std::string recording;
  std::size_t irs = 0;
  double span_s = 0;
  double row_nodes_mean = 0, row_nodes_max = 0;  ///< candidates per IR
  double pushed_max = 0;    ///< nodes the server's state pushed, largest over the IRs
  double stream_bytes = 0;  ///< as travelled: whole, in the zstd stream
  double sent_bytes = 0;    ///< the same, uncompressed
  double m_tilde_bytes = 0, rows_bytes = 0;  ///< M~'s forms: whole, compliance rows
};

/// Measures a recording whose condensed FEM IRs are sphere IRs (Error if it holds none);
/// `body`: the recorded session's body (the held nodes' free dofs).
SphereIrBytesRow measure_sphere_ir_bytes(const std::filesystem::path& recording,
                                         const ElasticBody& body);

/// `cohaptic-lab ir-bytes --scene SCENE RECORDING... [--frames DIR]`: a Markdown table on stdout.
LabCommand add_ir_bytes_command(CLI::App& lab);

}  // namespace cohaptic
