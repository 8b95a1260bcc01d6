// FEM against FEM on the network (end to end, the real programs on loopback): cohaptic-server
// serving the shipped scenes/objects/fem_pair.yaml (a soft slab A lying on a stiffer block B,
// both linear elastic) and two cohaptic-client processes pressing A with short scripts.
// Each user feels B through A (a 4 mm press on A alone gives 0.10 N, on B 0.43 N:
// FemPairScene.TheShippedScenesSurgeonsFeelBThroughA); while A pushes B its IRs travel with
// M~ whole though the server sends compliance rows otherwise (rows of A's own L would lose
// B); and the three recordings verify bit for bit (the clients' forces re-run from the IRs
// they received, the server's steps re-run from the tools it was given).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "lab/replay.h"
#include "support/process.h"

namespace cohaptic {
namespace {
namespace fs = std::filesystem;

// A press of 4 mm at (x, y) mm on A's upper face (z = 20 mm), a slide by `slide` mm in y, and back.
void write_fem_pair_press(const fs::path& file, double x, double y, double slide) {
  std::ofstream(file) << fmt::format(R"(
units: mm
start: [{0}, {1}, 24]
segments:
  - {{move_to: [{0}, {1}, 20.5], speed: 20}}
  - {{press: 4.5, speed: 5, direction: [0, 0, -1]}}
  - {{move_by: [0, {2}, 0], speed: 4}}
  - {{hold: 0.3}}
  - {{release: 4.5, speed: 5}}
)",
                                     x, y, slide);
}

TEST(FemPairSession, TwoUsersFeelBThroughAAndTheirRecordingsVerify) {
  const fs::path dir = testing::scratch_directory("fem-pair-session");
  write_fem_pair_press(dir / "a.yaml", -5, -6, 0);
  write_fem_pair_press(dir / "b.yaml", 14, 16, -6);
  testing::run_scripted_session(dir, fs::path(COHAPTIC_SOURCE_DIR) / "scenes/objects/fem_pair.yaml",
                                {"--duration", "60", "--no-disk-cache"},
                                {{"a", dir / "a.yaml"}, {"b", dir / "b.yaml"}});
  if (HasFatalFailure()) return;

  const nlohmann::json server_report = nlohmann::json::parse(std::ifstream(dir / "server.json"));
  EXPECT_EQ(server_report["server"]["failed_steps"]["count"], 0);
  for (const char* user : {"a", "b"}) {
    SCOPED_TRACE(user);
    const nlohmann::json report =
        nlohmann::json::parse(std::ifstream(dir / (std::string(user) + ".json")));
    EXPECT_EQ(report["non_finite_ticks"], 0);
    EXPECT_EQ(report["fades"]["count"], 0) << "the force faded while the user pushed";
    EXPECT_GT(report["force_n"]["peak"].get<double>(),
              0.2);  // B felt: on A alone a 4 mm press gives 0.10 N
    const int received = report["ir"]["received"], as_rows = report["ir"]["condensed"];
    EXPECT_EQ(report["ir"]["rejected"], 0);
    EXPECT_GT(received - as_rows, 0);  // M~ whole while A pushes B
  }
  for (const char* file : {"server.mcap", "a.mcap", "b.mcap"}) {
    const VerifyResult result = verify_recording(dir / file, SceneFileAccess{});
    EXPECT_TRUE(result.ok) << file << ": " << result.first_difference;
    EXPECT_GT(result.checked, 3u) << file;
  }
}

}  // namespace
}  // namespace cohaptic
