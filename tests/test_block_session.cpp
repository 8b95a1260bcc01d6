// Hundreds of nodes under a tool, on the network (end to end, the real programs on
// loopback): cohaptic-server serving the shipped scenes/block/two_spheres.yaml (a block
// gmsh grades to 0.6 mm under each of two 10 mm spheres) and two cohaptic-client processes
// pressing it 1 mm with scripted tools. Each IR carries the normal compliance of a few
// hundred candidate nodes (no cap), the clients push more than 100 nodes each at the
// deepest, the session is healthy by the demo's own verdict, and the three recordings
// verify bit for bit: each client's forces re-run, tick by tick in the order it used them,
// from the IRs it received (the offline evaluation of what it held), the server's steps
// from the tools it was given.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "common/ir/evaluate_force.h"
#include "lab/replay.h"
#include "lab/session_summary.h"
#include "proto/record/recording.h"
#include "proto/wire/ir_convert.h"
#include "support/process.h"

namespace cohaptic {
namespace {
namespace fs = std::filesystem;

// The server computes the touchable region's compliance at load unless its disk cache has
// it (about 40 s on this 2-core machine the first time).
constexpr std::chrono::milliseconds kColdLoad{300'000};

// A 10 mm sphere at x mm on the block's top: down to 0.5 mm above touching, 1.5 mm down
// (1 mm into the block), held, and back.
void write_block_press(const fs::path& file, double x) {
  std::ofstream(file) << fmt::format(R"(
units: mm
start: [{0}, 0, 12]
segments:
  - {{move_to: [{0}, 0, 10.5], speed: 20}}
  - {{press: 1.5, speed: 2, direction: [0, 0, -1]}}
  - {{hold: 0.5}}
  - {{release: 1.5, speed: 2}}
)",
                                     x);
}

TEST(BlockSession, TwoUsersPushHundredsOfNodesHealthyAndTheirRecordingsVerify) {
  const fs::path dir = testing::scratch_directory("block-session");
  write_block_press(dir / "a.yaml", -25);
  write_block_press(dir / "b.yaml", 25);
  testing::run_scripted_session(
      dir, fs::path(COHAPTIC_SOURCE_DIR) / "scenes/block/two_spheres.yaml", {"--duration", "400"},
      {{"a", dir / "a.yaml"}, {"b", dir / "b.yaml"}}, kColdLoad);
  if (HasFatalFailure()) return;

  const nlohmann::json server_report = nlohmann::json::parse(std::ifstream(dir / "server.json"));
  std::vector<nlohmann::json> client_reports;
  for (const char* user : {"a", "b"}) {
    SCOPED_TRACE(user);
    const nlohmann::json report =
        nlohmann::json::parse(std::ifstream(dir / (std::string(user) + ".json")));
    EXPECT_EQ(report["ir"]["rejected"], 0);
    EXPECT_EQ(report["contact_unresolved_ticks"], 0)
        << "every tick's contact solve finished in its budget";
    // Hertz gives 0.46 N at 1 mm; the block is finite and the other sphere presses too.
    EXPECT_NEAR(report["force_n"]["peak"].get<double>(), 0.47, 0.03);
    client_reports.push_back(report);

    // The IRs held hundreds of candidates, and more than 100 of them pushed at once.
    const record::Recording recording = record::read_recording(dir / (std::string(user) + ".mcap"));
    std::size_t most_rows = 0, most_contacts = 0;
    for (const record::RecordedIr& recorded : recording.irs) {
      const IntermediateRepresentation ir = wire::from_wire(recorded.ir());
      const CondensedFemIr& fem = condensed_fem(ir);
      ASSERT_TRUE(fem.sphere);
      most_rows = std::max(most_rows, static_cast<std::size_t>(fem.row_node_count));
      most_contacts = std::max(most_contacts, fem.sphere->contacts.size());
    }
    std::printf("  %s: %zu IRs, up to %zu row nodes and %zu nodes pushed; peak force %.4f N\n",
                user, recording.irs.size(), most_rows, most_contacts,
                report["force_n"]["peak"].get<double>());
    EXPECT_GT(most_rows, 200u);
    EXPECT_GT(most_contacts, 100u);
  }
  const SessionVerdict verdict = summarize_session(server_report, client_reports);
  EXPECT_TRUE(verdict.problems.empty()) << verdict.report["problems"].dump();
  for (const auto& [file, least] :
       {std::pair{"server.mcap", 3u}, {"a.mcap", 1000u}, {"b.mcap", 1000u}}) {
    const VerifyResult result = verify_recording(dir / file, SceneFileAccess{});
    EXPECT_TRUE(result.ok) << file << ": " << result.first_difference;
    EXPECT_GT(result.checked, least) << file;
  }
}

}  // namespace
}  // namespace cohaptic
