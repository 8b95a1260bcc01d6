#include "lab/ir_bytes.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <ctime>
#include <fstream>
#include <memory>
#include <optional>
#include <span>
#include <unordered_map>
#include <unordered_set>

#include "common/condense/naive_condensation.h"
#include "common/ir/client_condensation.h"
#include "common/mesh/tet_mesh.h"
#include "common/model/model.h"
#include "common/scene/load_scene.h"
#include "common/util/error.h"
#include "common/util/stopwatch.h"
#include "proto/record/recording.h"
#include "proto/wire/ir_convert.h"
#include "proto/wire/ir_stream.h"

namespace cohaptic {
namespace {

// Entries of L_AA (symmetric, 3 dofs per node) that involve at least one of `added` new
// nodes among `nodes`: the new nodes' rows against every node, each pair once.
double compliance_row_values(double nodes, double added) {
  return 9 * (added * nodes - added * (added - 1) / 2);
}

// Entries of `now` that differ from `before` bit for bit (same shape).
std::size_t changed_entries(const google::protobuf::RepeatedField<double>& before,
                            const google::protobuf::RepeatedField<double>& now) {
  std::size_t changed = 0;
  for (int i = 0; i < now.size(); ++i)
    if (std::memcmp(&before[i], &now[i], sizeof(double)) != 0) ++changed;
  return changed;
}

}  // namespace

IrBytesRow measure_ir_bytes(const std::filesystem::path& recording, const ElasticBody& body,
                            ComplianceColumns& columns, const std::filesystem::path& frames) {
  const record::Recording rec = record::read_recording(recording);
  const std::unordered_map<std::int64_t, int> node_of_tag = node_indices_by_tag(body.mesh);
  IrBytesRow row;
  row.recording = recording.string();
  if (!frames.empty()) std::filesystem::create_directories(frames);
  std::optional<wire::IntermediateRepresentation> previous;
  std::unordered_set<std::int64_t> previous_truncated;  // the held nodes it left out (B truncation)
  std::int64_t first_ns = 0, last_ns = 0;
  std::vector<double> client_us, completed_us;
  ClientCondensation client;
  wire::IrStreamWriter stream_out;
  wire::IrStreamReader stream_in;
  std::vector<double> inflate_us;
  for (const record::RecordedIr& recorded : rec.irs) {
    if (!recorded.ir().has_fem()) continue;
    {
      const wire::CompressedIr block =
          stream_out.compress(recorded.ir(), recorded.ir().fem().rows_generation() == 1);
      row.stream_bytes += static_cast<double>(block.ByteSizeLong());
      const double start_us = thread_cpu_us();
      const wire::IntermediateRepresentation opened = stream_in.open(block);
      inflate_us.push_back(thread_cpu_us() - start_us);
      if (opened.ByteSizeLong() != recorded.ir().ByteSizeLong())
        throw Error(fmt::format("ir-bytes: {}: IR epoch {} came out of the IR stream changed",
                                recording.string(), recorded.ir().epoch()));
    }
    // An IR that came as compliance rows is completed as the client did: the options are
    // measured against its whole-M~ form, "sent" is what came.
    wire::IntermediateRepresentation ir = recorded.ir();
    const std::string bytes = ir.SerializeAsString();
    // B truncation: held nodes the IR leaves out, which the client condenses over too.
    const std::vector<std::int64_t> truncated(ir.fem().truncated_node_ids().begin(),
                                              ir.fem().truncated_node_ids().end());
    if (ir.fem().rows_generation() > 0) {
      IntermediateRepresentation completed = wire::from_wire(ir);
      const double start_us = thread_cpu_us();
      client.complete(condensed_fem(completed));
      completed_us.push_back(thread_cpu_us() - start_us);
      ir = wire::to_wire(completed);
    }
    const wire::CondensedFem& fem = ir.fem();
    if (row.irs == 0) first_ns = recorded.time_ns();
    last_ns = recorded.time_ns();

    if (!frames.empty()) {
      std::ofstream out(frames / fmt::format("frame_{:06d}.bin", row.irs), std::ios::binary);
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      if (!out) throw Error(fmt::format("ir-bytes: cannot write into {}", frames.string()));
    }
    row.sent_bytes += static_cast<double>(bytes.size());

    const IntermediateRepresentation received = wire::from_wire(ir);
    IntermediateRepresentation rounded = received;
    condensed_fem(rounded).precision = IrPrecision::f32;
    row.f32_bytes += static_cast<double>(wire::to_wire(rounded).ByteSizeLong());

    wire::IntermediateRepresentation without_m = ir;
    without_m.mutable_fem()->clear_m_tilde_f64();
    without_m.mutable_fem()->clear_m_tilde_f32();
    const auto rest = static_cast<double>(without_m.ByteSizeLong());
    const double value_bytes = fem.m_tilde_f32_size() > 0 ? 4 : 8;
    const double m_bytes = static_cast<double>(ir.ByteSizeLong()) - rest;
    row.without_m_bytes += rest;

    const auto nodes = static_cast<double>(fem.node_ids_size());
    std::unordered_set<std::int64_t> had;
    if (previous) had.insert(previous->fem().node_ids().begin(), previous->fem().node_ids().end());
    double added = 0;
    for (const std::int64_t id : fem.node_ids()) added += had.contains(id) ? 0 : 1;
    row.nodes_mean += nodes;
    row.new_nodes_mean += added;

    const bool same_nodes =
        previous &&
        std::equal(fem.node_ids().begin(), fem.node_ids().end(), previous->fem().node_ids().begin(),
                   previous->fem().node_ids().end()) &&
        previous->fem().m_rows() == fem.m_rows() && previous->fem().m_cols() == fem.m_cols() &&
        fem.m_tilde_f64_size() > 0 && previous->fem().m_tilde_f64_size() == fem.m_tilde_f64_size();
    const double delta_m =
        same_nodes
            ? std::min(m_bytes, 12.0 * static_cast<double>(changed_entries(
                                           previous->fem().m_tilde_f64(), fem.m_tilde_f64())))
            : m_bytes;
    row.delta_bytes += rest + delta_m;
    // Rows go to every node the client holds: with B truncation the left-out ones too.
    double held_added = 0;
    const auto count_new = [&](std::int64_t id) {
      held_added += had.contains(id) || previous_truncated.contains(id) ? 0 : 1;
    };
    std::for_each(fem.node_ids().begin(), fem.node_ids().end(), count_new);
    std::for_each(truncated.begin(), truncated.end(), count_new);
    row.rows_bytes +=
        rest + value_bytes *
                   compliance_row_values(nodes + static_cast<double>(truncated.size()), held_added);

    const CondensedFemIr& sent = condensed_fem(received);
    std::vector<std::int64_t> held = sent.node_ids;
    held.insert(held.end(), truncated.begin(), truncated.end());
    std::vector<int> mesh_nodes;
    for (const std::int64_t tag : held) {
      const auto found = node_of_tag.find(tag);
      if (found == node_of_tag.end() || columns.row_position(found->second) < 0)
        throw Error(fmt::format(
            "ir-bytes: {}: IR epoch {} has node {}, which is no surface node of the scene's body",
            recording.string(), ir.epoch(), tag));
      mesh_nodes.push_back(found->second);
    }
    // The client's work under compliance rows: the naive condensation of L_AA (the server's
    // reference path), on the thread's CPU clock; the columns are solved before (a client
    // receives them).
    columns.compute_columns(mesh_nodes);
    const auto contact = static_cast<std::size_t>(sent.row_node_count);
    const double start_us = thread_cpu_us();
    const CondensedOperator op =
        naive_condensation(columns, body.dofs, std::span(mesh_nodes).first(contact),
                           std::span(mesh_nodes).subspan(contact));
    client_us.push_back(thread_cpu_us() - start_us);
    // The truncated nodes' columns (the last ones) are dropped, as the client drops them.
    const Eigen::Index kept_columns = sent.m_tilde.cols() - op.m_cc.cols();
    if (sent.m_tilde.rows() != op.m_cc.rows() || kept_columns < 0 || kept_columns > op.m_cb.cols())
      throw Error(fmt::format(
          "ir-bytes: {}: IR epoch {}: its M~ is {} x {}, its free dofs give {} x {} and {} held",
          recording.string(), ir.epoch(), sent.m_tilde.rows(), sent.m_tilde.cols(), op.m_cc.rows(),
          op.m_cc.cols(), op.m_cb.cols()));
    Eigen::MatrixXd condensed(op.m_cc.rows(), op.m_cc.cols() + kept_columns);
    condensed << op.m_cc, op.m_cb.leftCols(kept_columns);
    row.rows_m_tilde_difference =
        std::max(row.rows_m_tilde_difference, (condensed - sent.m_tilde).cwiseAbs().maxCoeff() /
                                                  sent.m_tilde.cwiseAbs().maxCoeff());

    previous = std::move(ir);
    previous_truncated = std::unordered_set<std::int64_t>(truncated.begin(), truncated.end());
    ++row.irs;
  }
  if (row.irs == 0)
    throw Error(fmt::format("ir-bytes: {} holds no condensed FEM IR", recording.string()));
  row.span_s = static_cast<double>(last_ns - first_ns) * 1e-9;
  row.nodes_mean /= static_cast<double>(row.irs);
  row.new_nodes_mean /= static_cast<double>(row.irs);
  std::sort(client_us.begin(), client_us.end());
  row.rows_client_us_p50 = client_us[client_us.size() / 2];
  row.rows_client_us_max = client_us.back();
  std::sort(inflate_us.begin(), inflate_us.end());
  row.stream_inflate_us_p50 = inflate_us[inflate_us.size() / 2];
  row.stream_inflate_us_max = inflate_us.back();
  if (!completed_us.empty()) {
    row.sent_rows_first_us = completed_us.front();
    std::sort(completed_us.begin(), completed_us.end());
    row.sent_rows_us_p50 = completed_us[completed_us.size() / 2];
    row.sent_rows_us_max = completed_us.back();
  }
  return row;
}

SphereIrBytesRow measure_sphere_ir_bytes(const std::filesystem::path& recording,
                                         const ElasticBody& body) {
  const record::Recording rec = record::read_recording(recording);
  const std::unordered_map<std::int64_t, int> node_of_tag = node_indices_by_tag(body.mesh);
  SphereIrBytesRow row;
  row.recording = recording.string();
  wire::IrStreamWriter stream;
  std::unordered_set<std::int64_t> held;  // the nodes a client of compliance rows would hold
  std::int64_t first_ns = 0, last_ns = 0;
  for (const record::RecordedIr& recorded : rec.irs) {
    if (!recorded.ir().has_fem() || !recorded.ir().fem().has_sphere()) continue;
    const wire::CondensedFem& fem = recorded.ir().fem();
    row.stream_bytes +=
        static_cast<double>(stream.compress(recorded.ir(), row.irs == 0).ByteSizeLong());
    row.sent_bytes += static_cast<double>(recorded.ir().ByteSizeLong());
    if (row.irs == 0) first_ns = recorded.time_ns();
    last_ns = recorded.time_ns();
    const auto nodes = static_cast<double>(fem.node_ids_size());
    row.row_nodes_mean += nodes;
    row.row_nodes_max = std::max(row.row_nodes_max, nodes);
    row.pushed_max = std::max(row.pushed_max, static_cast<double>(fem.sphere().contacts_size()));

    // M~'s forms: the same geometry with M~ (and u_B) instead of the sphere's part.
    wire::IntermediateRepresentation geometry = recorded.ir();
    geometry.mutable_fem()->clear_sphere();
    const auto rest = static_cast<double>(geometry.ByteSizeLong());
    double row_dofs = 0, held_dofs = 0;
    for (const char mask : fem.fixed_axes())
      for (int axis = 0; axis < 3; ++axis)
        row_dofs += ((static_cast<unsigned char>(mask) >> axis) & 1u) ? 0 : 1;
    for (const std::int64_t tag : fem.sphere().held_node_ids()) {
      const auto found = node_of_tag.find(tag);
      if (found == node_of_tag.end())
        throw Error(fmt::format(
            "ir-bytes: {}: IR epoch {} holds node {}, which the scene's body does not have",
            recording.string(), recorded.ir().epoch(), tag));
      for (int axis = 0; axis < 3; ++axis)
        held_dofs += body.dofs.is_fixed(found->second, axis) ? 0 : 1;
    }
    row.m_tilde_bytes += rest + 8 * (row_dofs * (row_dofs + held_dofs) + held_dofs);
    std::unordered_set<std::int64_t> now(fem.node_ids().begin(), fem.node_ids().end());
    now.insert(fem.sphere().held_node_ids().begin(), fem.sphere().held_node_ids().end());
    double added = 0;
    for (const std::int64_t tag : now) added += held.contains(tag) ? 0 : 1;
    row.rows_bytes += rest + 8 * compliance_row_values(static_cast<double>(now.size()), added);
    held = std::move(now);
    ++row.irs;
  }
  if (row.irs == 0) throw Error(fmt::format("ir-bytes: {} holds no sphere IR", recording.string()));
  row.span_s = static_cast<double>(last_ns - first_ns) * 1e-9;
  row.row_nodes_mean /= static_cast<double>(row.irs);
  return row;
}

LabCommand add_ir_bytes_command(CLI::App& lab) {
  struct Options {
    std::filesystem::path scene;
    std::vector<std::filesystem::path> recordings;
    std::filesystem::path frames;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = lab.add_subcommand("ir-bytes",
                                         "IR bytes per second a client received, and what f32, M~ "
                                         "deltas or compliance rows would have sent");
  command
      ->add_option("--scene", options->scene,
                   "The recorded session's scene (one linear elastic object)")
      ->required()
      ->check(CLI::ExistingFile);
  command
      ->add_option("recordings", options->recordings,
                   "Client recordings (cohaptic-client --record)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--frames", options->frames,
                      "Also write every IR as sent into this directory, one file each");
  return {
      command, [options] {
        const Model model = build_model(load_scene(options->scene));
        const ElasticBody& body = single_elastic_body(model);
        if (model.scene.haptic.contact_model == ContactModel::sphere) {
          fmt::print(
              "| recording | IRs | span s | row nodes per IR (largest) | pushed, largest | as "
              "sent: W whole in "
              "the zstd stream, kB/s | uncompressed kB/s | as M~ whole kB/s | as compliance rows "
              "kB/s |\n|---|---|---|---|---|---|---|---|---|\n");
          for (const std::filesystem::path& recording : options->recordings) {
            const SphereIrBytesRow r = measure_sphere_ir_bytes(recording, body);
            const double per_s = r.span_s > 0 ? 1e-3 / r.span_s : 0;
            fmt::print(
                "| {} | {} | {:.1f} | {:.0f} ({:.0f}) | {:.0f} | {:.1f} | {:.1f} | {:.1f} | {:.1f} "
                "|\n",
                r.recording, r.irs, r.span_s, r.row_nodes_mean, r.row_nodes_max, r.pushed_max,
                r.stream_bytes * per_s, r.sent_bytes * per_s, r.m_tilde_bytes * per_s,
                r.rows_bytes * per_s);
          }
          return 0;
        }
        ComplianceColumns columns(body.free_factor, body.dofs, body.surface.nodes);
        fmt::print(
            "| recording | IRs | span s | nodes per IR | new nodes per IR | sent kB/s | without M~ "
            "kB/s | f32 kB/s | "
            "M~ delta kB/s | compliance rows kB/s | rows: client CPU µs p50 / max | rows: M~ "
            "difference | "
            "as sent: client CPU µs p50 / max / first | zstd stream kB/s | zstd stream: client CPU "
            "µs p50 / max |\n"
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
        for (std::size_t i = 0; i < options->recordings.size(); ++i) {
          const std::filesystem::path frames =
              options->frames.empty() ? options->frames : options->frames / fmt::format("{}", i);
          const IrBytesRow r = measure_ir_bytes(options->recordings[i], body, columns, frames);
          const double per_s = r.span_s > 0 ? 1e-3 / r.span_s : 0;
          fmt::print(
              "| {} | {} | {:.1f} | {:.1f} | {:.2f} | {:.1f} | {:.1f} | {:.1f} | {:.1f} | {:.1f} | "
              "{:.0f} / {:.0f} | "
              "{:.1e} | {} | {:.1f} | {:.0f} / {:.0f} |\n",
              r.recording, r.irs, r.span_s, r.nodes_mean, r.new_nodes_mean, r.sent_bytes * per_s,
              r.without_m_bytes * per_s, r.f32_bytes * per_s, r.delta_bytes * per_s,
              r.rows_bytes * per_s, r.rows_client_us_p50, r.rows_client_us_max,
              r.rows_m_tilde_difference,
              r.sent_rows_us_max > 0 ? fmt::format("{:.0f} / {:.0f} / {:.0f}", r.sent_rows_us_p50,
                                                   r.sent_rows_us_max, r.sent_rows_first_us)
                                     : std::string("M~ sent whole"),
              r.stream_bytes * per_s, r.stream_inflate_us_p50, r.stream_inflate_us_max);
        }
        return 0;
      }};
}

}  // namespace cohaptic
