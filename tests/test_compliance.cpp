// Compliance columns against direct dense inverses, and the on-disk cache's validity rules.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <filesystem>
#include <fstream>

#include "common/fem/compliance.h"
#include "common/fem/compliance_disk_cache.h"
#include "common/model/compliance_setup.h"
#include "common/model/model.h"
#include "common/model/scene_compliance.h"
#include "common/scene/load_scene.h"
#include "support/scratch_directory.h"

namespace cohaptic {
namespace {

using testing::ScratchDirectory;

namespace fs = std::filesystem;

std::string small_cube_yaml(double youngs_modulus = 1e6, int divisions = 4,
                            const char* precompute = "touchable") {
  return fmt::format(R"(
units: mm
objects:
  - name: cube
    mesh: {{box: {{min: [-65, -65, -130], size: [130, 130, 130], divisions: [{0}, {0}, {0}]}}}}
    material: {{youngs_modulus: {1}, poisson_ratio: 0.4}}
    fixed: [{{plane: {{point: [0, 0, -130], normal: [0, 0, 1]}}}}]
    touchable: [{{plane: {{point: [0, 0, 0], normal: [0, 0, 1]}}}}]
    compliance: {{precompute: {2}}}
tools: [{{name: A}}]
)",
                     divisions, youngs_modulus, precompute);
}

TEST(Compliance, ColumnsEqualTheDenseInverseAndAreSymmetric) {
  const Model model = build_model(parse_scene(small_cube_yaml(), "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(body.free_factor, body.dofs, body.touchable_nodes);
  const Eigen::MatrixXd k_ff(restrict_to_dofs(body.stiffness, body.dofs.free_dofs));
  const Eigen::MatrixXd inverse =
      k_ff.ldlt().solve(Eigen::MatrixXd::Identity(k_ff.rows(), k_ff.cols()));
  for (int i : {0, 7, 24})
    for (int j : {0, 3, 24}) {
      const int a = body.touchable_nodes[i], b = body.touchable_nodes[j];
      Eigen::Matrix3d expected;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          expected(r, c) =
              inverse(body.dofs.free_index[3 * a + r], body.dofs.free_index[3 * b + c]);
      EXPECT_LE((columns.block(a, b) - expected).norm(), 1e-10 * expected.norm());
      EXPECT_LE((columns.block(a, b) - columns.block(b, a).transpose()).norm(),
                1e-12 * expected.norm());
    }
  // One at a time or all at once: the same numbers.
  ComplianceColumns batch(body.free_factor, body.dofs, body.touchable_nodes);
  batch.compute_columns(body.touchable_nodes);
  for (int node : body.touchable_nodes)
    EXPECT_LE((batch.column(node) - columns.column(node)).norm(),
              1e-13 * batch.column(node).norm());
}

TEST(Compliance, AColumnsBitsDoNotDependOnWhatElseWasAskedFor) {
  // Replays rebuild M~ bit for bit only if they do: a solve's rounding depends on how many
  // right-hand sides it has, so columns are always solved in the same groups.
  const Model model = build_model(parse_scene(small_cube_yaml(1e6, 8), "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns one_by_one(body.free_factor, body.dofs, body.surface.nodes);
  ComplianceColumns all_at_once(body.free_factor, body.dofs, body.surface.nodes);
  all_at_once.compute_columns(body.surface.nodes);
  for (std::size_t i = 0; i < body.surface.nodes.size(); i += 7) {
    const int node = body.surface.nodes[i];
    const ComplianceColumn& a = one_by_one.column(node);
    const ComplianceColumn& b = all_at_once.column(node);
    ASSERT_EQ(std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())),
              0)
        << "node " << node;
  }
}

TEST(ComplianceCache, KeyChangesWithMeshMaterialBoundaryConditionsRowsAndRoute) {
  const Model model = build_model(parse_scene(small_cube_yaml(), "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  const auto key = [&](const TetMesh& mesh, const LinearElasticMaterial& material,
                       const DofMap& dofs, const std::vector<int>& rows) {
    return compliance_cache_key(mesh, material, dofs, rows, ComplianceRoute::solves);
  };
  const LinearElasticMaterial material = body.spec.material;
  const Digest base = key(body.mesh, material, body.dofs, body.touchable_nodes);
  EXPECT_EQ(base, key(body.mesh, material, body.dofs, body.touchable_nodes));

  TetMesh moved = body.mesh;
  moved.nodes(1, 40) += 1e-12;
  EXPECT_NE(base, key(moved, material, body.dofs, body.touchable_nodes));
  TetMesh renumbered = body.mesh;
  std::swap(renumbered.tets[0][1], renumbered.tets[0][2]);
  EXPECT_NE(base, key(renumbered, material, body.dofs, body.touchable_nodes));
  EXPECT_NE(base, key(body.mesh, {material.youngs_modulus * 1.000001, material.poisson_ratio},
                      body.dofs, body.touchable_nodes));
  EXPECT_NE(base, key(body.mesh, {material.youngs_modulus, 0.3}, body.dofs, body.touchable_nodes));
  std::vector<AxisMask> fixed = body.dofs.fixed_axes;
  fixed[body.touchable_nodes[0]] = 0b100;  // one more node sliding
  EXPECT_NE(base, key(body.mesh, material, make_dof_map(fixed), body.touchable_nodes));
  std::vector<int> fewer_rows(body.touchable_nodes.begin() + 1, body.touchable_nodes.end());
  EXPECT_NE(base, key(body.mesh, material, body.dofs, fewer_rows));
  EXPECT_NE(base, compliance_cache_key(body.mesh, material, body.dofs, body.touchable_nodes,
                                       ComplianceRoute::schur));
}

TEST(ComplianceCache, RoundTripsBitExactlyAndIsUsedOnTheSecondRun) {
  const ScratchDirectory dir;
  const Model model = build_model(parse_scene(small_cube_yaml(), "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns first(body.free_factor, body.dofs, compliance_row_nodes(body, false));
  const ComplianceSetup computed = prepare_compliance(body, first, dir.path);
  EXPECT_FALSE(computed.from_disk);
  EXPECT_TRUE(fs::exists(computed.cache_file));

  ComplianceColumns second(body.free_factor, body.dofs, compliance_row_nodes(body, false));
  const ComplianceSetup loaded = prepare_compliance(body, second, dir.path);
  EXPECT_TRUE(loaded.from_disk);
  ASSERT_EQ(second.column_count(), first.column_count());
  for (const auto& [node, column] : first.columns())
    EXPECT_EQ(std::memcmp(column.data(), second.columns().at(node).data(),
                          sizeof(double) * column.size()),
              0);
}

TEST(ComplianceCache, KffIsFactoredAtLoadOnlyWhenARowsColumnIsLeftToSolve) {
  const ScratchDirectory dir;
  {
    // Columns solved on demand: K_ff is factored while the compliance is prepared, so that
    // the first column is never a first factorisation in the middle of a session.
    const Model model = build_model(parse_scene(small_cube_yaml(1e6, 4, "on_demand"), "cube.yaml"));
    const ElasticBody& body = single_elastic_body(model);
    ComplianceColumns columns(body.free_factor, body.dofs, compliance_row_nodes(body, false));
    prepare_compliance(body, columns, std::nullopt);
    EXPECT_TRUE(body.free_factor.factored());
  }
  {
    // Every row's column made at load by the Schur complement (its own factorisation):
    // K_ff's is never needed.
    const Model model = build_model(parse_scene(small_cube_yaml(), "cube.yaml"));
    const ElasticBody& body = single_elastic_body(model);
    EXPECT_FALSE(body.free_factor.factored());
    ComplianceColumns columns(body.free_factor, body.dofs, compliance_row_nodes(body, false));
    EXPECT_FALSE(prepare_compliance(body, columns, dir.path).from_disk);
    EXPECT_FALSE(body.free_factor.factored());
  }
  // Warm: every row's column comes from the file, and K_ff is not factored.
  const Model model = build_model(parse_scene(small_cube_yaml(), "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(body.free_factor, body.dofs, compliance_row_nodes(body, false));
  EXPECT_TRUE(prepare_compliance(body, columns, dir.path).from_disk);
  EXPECT_FALSE(body.free_factor.factored());
  // A column outside the rows (an interior node's) is solved when asked for: against the
  // dense inverse, as any other.
  int interior = 0;
  while (columns.row_position(interior) >= 0 || body.dofs.fixed_axes[interior] != 0) ++interior;
  const ComplianceColumn& column = columns.column(interior);
  EXPECT_TRUE(body.free_factor.factored());
  const Eigen::MatrixXd k_ff(restrict_to_dofs(body.stiffness, body.dofs.free_dofs));
  const Eigen::MatrixXd inverse =
      k_ff.ldlt().solve(Eigen::MatrixXd::Identity(k_ff.rows(), k_ff.cols()));
  const int row_node = columns.row_nodes().front();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(
          column(r, c),
          inverse(body.dofs.free_index[3 * row_node + r], body.dofs.free_index[3 * interior + c]),
          1e-10 * inverse.norm());
}

TEST(ComplianceCache, TruncatedOrCorruptedFilesAreDetectedAndRebuilt) {
  const ScratchDirectory dir;
  const Model model = build_model(parse_scene(small_cube_yaml(), "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns reference(body.free_factor, body.dofs, compliance_row_nodes(body, false));
  const fs::path file = prepare_compliance(body, reference, dir.path).cache_file;
  const auto size = fs::file_size(file);
  const Digest key = compliance_cache_key(body.mesh, body.spec.material, body.dofs,
                                          reference.row_nodes(), ComplianceRoute::schur);

  const auto expect_rebuilt = [&](const std::string& what) {
    ComplianceColumns probe(body.free_factor, body.dofs, compliance_row_nodes(body, false));
    const ComplianceCacheLoad load = load_compliance_cache(file, key, probe);
    EXPECT_FALSE(load.loaded) << what;
    EXPECT_EQ(probe.column_count(), 0u) << what << ": a bad file must insert nothing";
    EXPECT_FALSE(load.problem.empty()) << what;
    ComplianceColumns rebuilt(body.free_factor, body.dofs, compliance_row_nodes(body, false));
    const ComplianceSetup setup = prepare_compliance(body, rebuilt, dir.path);
    EXPECT_FALSE(setup.from_disk) << what;
    EXPECT_EQ(rebuilt.column_count(), reference.column_count()) << what;
    EXPECT_EQ(fs::file_size(file), size) << what << ": the cache is written again in full";
    ComplianceColumns reloaded(body.free_factor, body.dofs, compliance_row_nodes(body, false));
    EXPECT_TRUE(load_compliance_cache(file, key, reloaded).loaded) << what;
  };

  fs::resize_file(file, size / 2);
  expect_rebuilt("truncated to half");
  fs::resize_file(file, 10);
  expect_rebuilt("truncated to 10 bytes");
  {
    std::fstream io(file, std::ios::in | std::ios::out | std::ios::binary);
    io.seekp(static_cast<std::streamoff>(size / 3));
    char byte = 0;
    io.read(&byte, 1);
    io.seekp(static_cast<std::streamoff>(size / 3));
    byte = static_cast<char>(byte ^ 0x10);
    io.write(&byte, 1);
  }
  expect_rebuilt("one bit flipped");
}

TEST(ComplianceCache, AFileForAnotherMaterialIsNotUsed) {
  const ScratchDirectory dir;
  const Model soft_model = build_model(parse_scene(small_cube_yaml(1e6), "cube.yaml"));
  const Model stiff_model = build_model(parse_scene(small_cube_yaml(2e6), "cube.yaml"));
  const ElasticBody& soft = single_elastic_body(soft_model);
  const ElasticBody& stiff = single_elastic_body(stiff_model);
  ComplianceColumns soft_columns(soft.free_factor, soft.dofs, compliance_row_nodes(soft, false));
  const fs::path soft_file = prepare_compliance(soft, soft_columns, dir.path).cache_file;
  // Put the soft cache where the stiff one would be: its embedded key still tells them apart.
  ComplianceColumns stiff_columns(stiff.free_factor, stiff.dofs,
                                  compliance_row_nodes(stiff, false));
  const Digest stiff_key = compliance_cache_key(stiff.mesh, stiff.spec.material, stiff.dofs,
                                                stiff_columns.row_nodes(), ComplianceRoute::schur);
  fs::copy_file(soft_file, compliance_cache_file(dir.path, stiff_key));
  const ComplianceCacheLoad load =
      load_compliance_cache(compliance_cache_file(dir.path, stiff_key), stiff_key, stiff_columns);
  EXPECT_FALSE(load.loaded);
  EXPECT_NE(load.problem.find("different mesh, material or boundary conditions"), std::string::npos)
      << load.problem;
  // And the stiff object's compliance is half the soft one's (linear in 1/E).
  const int node = soft.touchable_nodes[5];
  EXPECT_LE((stiff_columns.column(node) * 2 - soft_columns.column(node)).norm(),
            1e-9 * soft_columns.column(node).norm());
}

TEST(ComplianceCache, AnUnwritableCacheDirectoryIsNotFatal) {
  const ScratchDirectory dir;
  const fs::path blocked = dir.path / "not-a-directory";
  std::ofstream(blocked) << "a file where the cache directory should be";
  const Model model = build_model(parse_scene(small_cube_yaml(), "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(body.free_factor, body.dofs, compliance_row_nodes(body, false));
  ComplianceSetup setup;
  EXPECT_NO_THROW(setup = prepare_compliance(body, columns, blocked / "cache"));
  EXPECT_EQ(columns.column_count(), body.touchable_nodes.size());
  EXPECT_THROW(save_compliance_cache(blocked / "cache" / "x.bin", Digest{}, columns), Error);
}

TEST(ComplianceCache, OnDemandModeComputesNothingUpFrontAndSavesWhatItComputed) {
  const ScratchDirectory dir;
  const Model model = build_model(parse_scene(small_cube_yaml(1e6, 4, "on_demand"), "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(body.free_factor, body.dofs, compliance_row_nodes(body, false));
  EXPECT_EQ(prepare_compliance(body, columns, dir.path).columns, 0u);
  // Rows 1 and 2 are in the same solve group (the first kGroupSize rows).
  static_assert(ComplianceColumns::kGroupSize > 2);
  columns.column(columns.row_nodes()[1]);
  columns.column(columns.row_nodes()[2]);
  save_compliance(body, columns, dir.path);
  ComplianceColumns again(body.free_factor, body.dofs, compliance_row_nodes(body, false));
  const ComplianceSetup setup = prepare_compliance(body, again, dir.path);
  EXPECT_TRUE(setup.from_disk);
  EXPECT_EQ(again.column_count(),
            static_cast<std::size_t>(ComplianceColumns::kGroupSize));  // that group's columns
  EXPECT_LT(again.column_count(), body.touchable_nodes.size());
  EXPECT_TRUE(again.has_column(columns.row_nodes()[2]));
}

// At a session's end the cache is written only when the session computed columns: a
// precomputed scene's session leaves its cache file alone.
TEST(ComplianceCache, ASessionThatComputedNoColumnsWritesNoCache) {
  const ScratchDirectory dir;
  const Model model = build_model(parse_scene(small_cube_yaml(1e6, 4, "on_demand"), "cube.yaml"));
  const SceneCompliance compliance = prepare_scene_compliance(model, false, dir.path);
  save_scene_compliance(model, compliance, dir.path);
  EXPECT_TRUE(fs::is_empty(dir.path)) << "nothing computed, nothing saved";
  ComplianceColumns& columns = *compliance.per_body[0];
  columns.column(columns.row_nodes()[1]);
  save_scene_compliance(model, compliance, dir.path);
  EXPECT_FALSE(fs::is_empty(dir.path)) << "the columns computed on demand are saved";
}

}  // namespace
}  // namespace cohaptic
