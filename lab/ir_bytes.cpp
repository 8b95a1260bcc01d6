#include "lab/ir_bytes.h"

#include <CLI/CLI.hpp>
#include <Eigen/Cholesky>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <unordered_set>
#include <utility>

#include "common/util/error.h"
#include "proto/record/recording.h"
#include "proto/wire/ir_convert.h"

namespace cohaptic {
namespace {

// Entries of L_AA (symmetric, 3 dofs per node) that involve at least one of `added` new
// nodes among `nodes`: the new nodes' rows against every node, each pair once.
double compliance_row_values(double nodes, double added) { return 9 * (added * nodes - added * (added - 1) / 2); }

// Entries of `now` that differ from `before` bit for bit (same shape).
std::size_t changed_entries(const google::protobuf::RepeatedField<double>& before,
                            const google::protobuf::RepeatedField<double>& now) {
  std::size_t changed = 0;
  for (int i = 0; i < now.size(); ++i)
    if (std::memcmp(&before[i], &now[i], sizeof(double)) != 0) ++changed;
  return changed;
}

// CPU time [µs] of what a client would do per IR under the compliance-rows option: factor a
// `dofs` x `dofs` SPD block and solve for `row_dofs` columns of its inverse. The matrix is
// diagonally dominant (hence SPD) and synthetic: the cost depends on the sizes only.
double condensation_us(int dofs, int row_dofs) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-1, 1);
  Eigen::MatrixXd block(dofs, dofs);
  for (int j = 0; j < dofs; ++j)
    for (int i = 0; i <= j; ++i) block(i, j) = block(j, i) = uniform(random);
  block.diagonal().array() += 2.0 * dofs;
  const Eigen::MatrixXd unit = Eigen::MatrixXd::Identity(dofs, row_dofs);
  double best = 1e300;
  for (int repeat = 0; repeat < 3; ++repeat) {
    const auto start = std::chrono::steady_clock::now();
    const Eigen::LLT<Eigen::MatrixXd> factor(block);
    const Eigen::MatrixXd rows = factor.solve(unit);
    const auto stop = std::chrono::steady_clock::now();
    if (!rows.allFinite()) throw Error("ir-bytes: the timing matrix did not factor");
    best = std::min(best, std::chrono::duration<double, std::micro>(stop - start).count());
  }
  return best;
}

}  // namespace

IrBytesRow measure_ir_bytes(const std::filesystem::path& recording, const std::filesystem::path& frames) {
  const record::Recording rec = record::read_recording(recording);
  IrBytesRow row;
  row.recording = recording.string();
  if (!frames.empty()) std::filesystem::create_directories(frames);
  const wire::IntermediateRepresentation* previous = nullptr;
  std::int64_t first_ns = 0, last_ns = 0;
  std::map<std::pair<int, int>, double> us_by_size;
  std::vector<double> client_us;
  for (const record::RecordedIr& recorded : rec.irs) {
    const wire::IntermediateRepresentation& ir = recorded.ir();
    if (!ir.has_fem()) continue;
    const wire::CondensedFem& fem = ir.fem();
    if (row.irs == 0) first_ns = recorded.time_ns();
    last_ns = recorded.time_ns();

    const std::string bytes = ir.SerializeAsString();
    if (!frames.empty()) {
      std::ofstream out(frames / fmt::format("frame_{:06d}.bin", row.irs), std::ios::binary);
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      if (!out) throw Error(fmt::format("ir-bytes: cannot write into {}", frames.string()));
    }
    row.sent_bytes += static_cast<double>(bytes.size());

    IntermediateRepresentation rounded = wire::from_wire(ir);
    condensed_fem(rounded).precision = IrPrecision::f32;
    row.f32_bytes += static_cast<double>(wire::to_wire(rounded).ByteSizeLong());

    wire::IntermediateRepresentation without_m = ir;
    without_m.mutable_fem()->clear_m_tilde_f64();
    without_m.mutable_fem()->clear_m_tilde_f32();
    const auto rest = static_cast<double>(without_m.ByteSizeLong());
    const double value_bytes = fem.m_tilde_f32_size() > 0 ? 4 : 8;
    const double m_bytes = static_cast<double>(bytes.size()) - rest;
    row.without_m_bytes += rest;

    const auto nodes = static_cast<double>(fem.node_ids_size());
    std::unordered_set<std::int64_t> had;
    if (previous) had.insert(previous->fem().node_ids().begin(), previous->fem().node_ids().end());
    double added = 0;
    for (const std::int64_t id : fem.node_ids()) added += had.contains(id) ? 0 : 1;
    row.nodes_mean += nodes;
    row.new_nodes_mean += added;

    const bool same_nodes = previous && std::equal(fem.node_ids().begin(), fem.node_ids().end(),
                                                   previous->fem().node_ids().begin(), previous->fem().node_ids().end()) &&
                            previous->fem().m_rows() == fem.m_rows() && previous->fem().m_cols() == fem.m_cols() &&
                            fem.m_tilde_f64_size() > 0 && previous->fem().m_tilde_f64_size() == fem.m_tilde_f64_size();
    const double delta_m =
        same_nodes ? std::min(m_bytes, 12.0 * static_cast<double>(changed_entries(previous->fem().m_tilde_f64(), fem.m_tilde_f64())))
                   : m_bytes;
    row.delta_bytes += rest + delta_m;
    row.rows_bytes += rest + value_bytes * compliance_row_values(nodes, added);

    const std::pair<int, int> size{3 * fem.node_ids_size(), static_cast<int>(3 * fem.row_node_count())};
    auto timed = us_by_size.find(size);
    if (timed == us_by_size.end()) timed = us_by_size.emplace(size, condensation_us(size.first, size.second)).first;
    client_us.push_back(timed->second);

    previous = &ir;
    ++row.irs;
  }
  if (row.irs == 0) throw Error(fmt::format("ir-bytes: {} holds no condensed FEM IR", recording.string()));
  row.span_s = static_cast<double>(last_ns - first_ns) * 1e-9;
  row.nodes_mean /= static_cast<double>(row.irs);
  row.new_nodes_mean /= static_cast<double>(row.irs);
  std::sort(client_us.begin(), client_us.end());
  row.rows_client_us_p50 = client_us[client_us.size() / 2];
  row.rows_client_us_max = client_us.back();
  return row;
}

LabCommand add_ir_bytes_command(CLI::App& lab) {
  struct Options {
    std::vector<std::filesystem::path> recordings;
    std::filesystem::path frames;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = lab.add_subcommand(
      "ir-bytes", "IR bytes per second a client received, and what f32, M~ deltas or compliance rows would have sent");
  command->add_option("recordings", options->recordings, "Client recordings (cohaptic-client --record)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--frames", options->frames, "Also write every IR as sent into this directory, one file each");
  return {command, [options] {
            fmt::print("| recording | IRs | span s | nodes per IR | new nodes per IR | sent kB/s | without M~ kB/s | f32 kB/s | M~ delta kB/s | "
                       "compliance rows kB/s | rows: client µs p50 / max |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
            for (std::size_t i = 0; i < options->recordings.size(); ++i) {
              const std::filesystem::path frames =
                  options->frames.empty() ? options->frames : options->frames / fmt::format("{}", i);
              const IrBytesRow r = measure_ir_bytes(options->recordings[i], frames);
              const double per_s = r.span_s > 0 ? 1e-3 / r.span_s : 0;
              fmt::print("| {} | {} | {:.1f} | {:.1f} | {:.2f} | {:.1f} | {:.1f} | {:.1f} | {:.1f} | {:.1f} | {:.0f} / {:.0f} |\n",
                         r.recording, r.irs, r.span_s, r.nodes_mean, r.new_nodes_mean, r.sent_bytes * per_s, r.without_m_bytes * per_s,
                         r.f32_bytes * per_s, r.delta_bytes * per_s, r.rows_bytes * per_s, r.rows_client_us_p50,
                         r.rows_client_us_max);
            }
            return 0;
          }};
}

}  // namespace cohaptic
