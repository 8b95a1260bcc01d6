// cohaptic-lab ir-bytes against counts made here by hand on a recording of three cube IRs:
// the first (no held nodes), the same IR again (an unchanged M~: the delta and the
// compliance-rows options send nothing of it), and one with held boundary nodes added (the
// compliance rows of exactly those nodes, against every node of the IR), and the M~ a client
// would condense from those rows equal to the server's.
#include <gtest/gtest.h>

#include <filesystem>
#include <vector>

#include "common/contact/nearest_surface_nodes.h"
#include "common/ir/build_ir.h"
#include "lab/ir_bytes.h"
#include "proto/record/session_recorder.h"
#include "proto/wire/ir_convert.h"
#include "support/cube_scene.h"

namespace cohaptic {
namespace {

double without_m_tilde(const wire::IntermediateRepresentation& ir) {
  wire::IntermediateRepresentation copy = ir;
  copy.mutable_fem()->clear_m_tilde_f64();
  return static_cast<double>(copy.ByteSizeLong());
}

TEST(IrBytes, CountsWhatEachOptionWouldSendOnARecording) {
  testing::CubeSceneOptions cube;
  cube.divisions = 6;
  const testing::CubeRig rig(cube);
  const ElasticBody& body = rig.body;
  const Eigen::Vector3d tool(0.004, -0.001, -0.002);
  const std::vector<UserTool> users = {{0, tool, 0, nearest_touchable_triangle(body, tool), {}}};
  IncrementalCondensation condensation(*rig.columns, body.dofs);
  const auto build = [&](std::span<const Eigen::Vector3d> held, std::uint64_t epoch) {
    return wire::to_wire(
        build_ir(body, condensation, users, 0, held, IrBuildOptions{}, epoch, 0.0));
  };
  const wire::IntermediateRepresentation first = build({}, 1);
  const wire::IntermediateRepresentation again = build({}, 2);
  std::vector<bool> under_tool(static_cast<std::size_t>(body.mesh.node_count()), false);
  for (int v : body.surface.triangles[users[0].nearest_triangle])
    under_tool[static_cast<std::size_t>(v)] = true;
  const std::vector<Eigen::Vector3d> around = {tool};
  std::vector<int> held =
      nearest_surface_nodes(body.mesh, body.surface, body.dofs, around, 30, under_tool);
  held.erase(held.begin(), held.begin() + 20);  // outside the patch: 10 held nodes
  condensation.set_boundary_nodes(held);
  const std::vector<Eigen::Vector3d> displacement(held.size(), Eigen::Vector3d(1e-4, 0, 0));
  const wire::IntermediateRepresentation more = build(displacement, 3);
  const int n = first.fem().node_ids_size();
  const int k = static_cast<int>(held.size());
  ASSERT_EQ(more.fem().node_ids_size(), n + k);

  const std::filesystem::path file =
      std::filesystem::path(::testing::TempDir()) / "ir_bytes_client.mcap";
  {
    record::SessionRecorder recorder(file);
    record::SessionConfig config;
    config.set_role("client");
    recorder.config(config);
    recorder.ir(1'000'000'000, first);
    recorder.ir(1'500'000'000, again);
    recorder.ir(3'000'000'000, more);
    recorder.close();
  }
  const std::filesystem::path frames =
      std::filesystem::path(::testing::TempDir()) / "ir_bytes_frames";
  std::filesystem::remove_all(frames);
  const IrBytesRow row = measure_ir_bytes(file, body, *rig.columns, frames);

  const double sizes[] = {static_cast<double>(first.ByteSizeLong()),
                          static_cast<double>(again.ByteSizeLong()),
                          static_cast<double>(more.ByteSizeLong())};
  EXPECT_EQ(row.irs, 3u);
  EXPECT_DOUBLE_EQ(row.span_s, 2.0);
  EXPECT_DOUBLE_EQ(row.sent_bytes, sizes[0] + sizes[1] + sizes[2]);
  EXPECT_DOUBLE_EQ(row.nodes_mean, (n + n + n + k) / 3.0);
  EXPECT_DOUBLE_EQ(row.new_nodes_mean, (n + 0 + k) / 3.0);
  EXPECT_LT(row.f32_bytes, row.sent_bytes);
  // Delta: M~ whole in the first, nothing of it in the repeat, whole again when the nodes change.
  EXPECT_DOUBLE_EQ(row.delta_bytes, sizes[0] + without_m_tilde(again) + sizes[2]);
  // Compliance rows: the whole upper triangle of L_AA (3 dofs a node) first, none for the
  // repeat, then the k new nodes' rows against all n + k nodes (each pair once), 8 bytes a value.
  const double whole = 9.0 * n * (n + 1) / 2;
  const double added = 9.0 * (k * (n + k) - k * (k - 1) / 2.0);
  EXPECT_DOUBLE_EQ(row.rows_bytes, without_m_tilde(first) + 8 * whole + without_m_tilde(again) +
                                       without_m_tilde(more) + 8 * added);
  EXPECT_DOUBLE_EQ(row.without_m_bytes,
                   without_m_tilde(first) + without_m_tilde(again) + without_m_tilde(more));
  EXPECT_GT(row.rows_client_us_p50, 0);
  // The client's own condensation of L_AA gives the server's M~ (its incremental
  // condensation) to rounding: that way of sending changes no force.
  EXPECT_LT(row.rows_m_tilde_difference, 1e-9);
  // The frames as sent, one file each, for a compressor.
  EXPECT_EQ(std::filesystem::file_size(frames / "frame_000002.bin"), more.ByteSizeLong());
  std::filesystem::remove_all(frames);
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace cohaptic
