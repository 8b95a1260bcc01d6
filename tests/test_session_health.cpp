// The verdict judges what the users felt (end to end, the real programs on loopback): one
// surgeon presses the cube 0.75 mm (about 1 N) and lets go. Served at the rate the machine allows the
// session is healthy; the same session with the server held to 2 steps a second (far below
// the scene's 20 Hz target) is UNHEALTHY, and the verdict names the starved step rate and
// the stale IRs, not something else.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "lab/session_summary.h"
#include "support/cube_scene.h"
#include "support/process.h"

namespace cohaptic {
namespace {
namespace fs = std::filesystem;

// The session in a fresh directory, the server given `server_arguments`; its verdict.
SessionVerdict press_the_cube(const std::string& name, const std::vector<std::string>& server_arguments) {
  const fs::path dir = testing::scratch_directory(name);
  testing::CubeSceneOptions cube;
  cube.divisions = 6;
  cube.youngs_modulus = 2.0e5;
  cube.touchable = "{surface: true}";
  cube.compliance = "{precompute: touchable, disk_cache: false}";
  cube.tools = "[{name: A}]";
  std::ofstream(dir / "cube.yaml") << testing::cube_scene_yaml(cube);
  std::ofstream(dir / "a.yaml") << R"(
units: mm
start: [4, 3, 4]
segments:
  - {move_to: [4, 3, 0.5], speed: 20}
  - {press: 1.25, speed: 1.5, direction: [0, 0, -1]}
  - {hold: 0.5}
  - {release: 1.25, speed: 1.5}
)";
  testing::run_scripted_session(dir, dir / "cube.yaml", server_arguments, {{"a", dir / "a.yaml"}});
  const nlohmann::json server = nlohmann::json::parse(std::ifstream(dir / "server.json"));
  return summarize_session(server, {nlohmann::json::parse(std::ifstream(dir / "a.json"))});
}

bool mentions(const std::vector<std::string>& lines, const std::string& text) {
  for (const std::string& line : lines)
    if (line.find(text) != std::string::npos) return true;
  return false;
}

TEST(SessionHealth, AStarvedServerIsUnhealthyNamingItsStepRateAndTheSameSessionFedIsHealthy) {
  const SessionVerdict fed = press_the_cube("health-fed", {});
  if (HasFatalFailure()) return;
  EXPECT_TRUE(fed.problems.empty()) << fed.report["problems"].dump(1);

  const SessionVerdict starved = press_the_cube("health-starved", {"--sim-rate-hz", "2"});
  if (HasFatalFailure()) return;
  EXPECT_FALSE(starved.report["healthy"].get<bool>());
  EXPECT_TRUE(mentions(starved.problems, "Hz, below 90 % of its target 20 Hz: capped by --sim-rate-hz 2"))
      << starved.report["problems"].dump(1);
  EXPECT_TRUE(mentions(starved.problems, "a: IR age p99")) << starved.report["problems"].dump(1);
  for (const std::string& problem : starved.problems)
    EXPECT_TRUE(problem.find("step") != std::string::npos || problem.find("IR age") != std::string::npos ||
                problem.find("faded") != std::string::npos)
        << "a cause other than the starved server: " << problem;
}

}  // namespace
}  // namespace cohaptic
