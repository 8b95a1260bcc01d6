// The verdict judges what the users felt (end to end, the real programs on loopback). One
// surgeon presses the cube 0.75 mm (about 1 N) and lets go; two surgeons press the rope
// lying on a block (scenes/objects/paired_boxes.yaml, a mass-spring body on a linear
// elastic one, one pass of its shipped scripts). Served at the rate the machine allows each
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

// `users` (each playing dir/<user>.yaml) on `scene`, the server given `server_arguments`: the
// session's verdict.
SessionVerdict verdict_of(const fs::path& dir, const fs::path& scene,
                          const std::vector<std::string>& server_arguments,
                          const std::vector<std::string>& users) {
  std::vector<std::pair<std::string, fs::path>> scripts;
  for (const std::string& user : users) scripts.emplace_back(user, dir / (user + ".yaml"));
  testing::run_scripted_session(dir, scene, server_arguments, scripts);
  std::vector<nlohmann::json> clients;
  for (const std::string& user : users)
    clients.push_back(nlohmann::json::parse(std::ifstream(dir / (user + ".json"))));
  return summarize_session(nlohmann::json::parse(std::ifstream(dir / "server.json")), clients);
}

// The cube session in a fresh directory, the server given `server_arguments`; its verdict.
SessionVerdict press_the_cube(const std::string& name,
                              const std::vector<std::string>& server_arguments) {
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
  return verdict_of(dir, dir / "cube.yaml", server_arguments, {"a"});
}

// The rope on the block, each shipped surgeon's script played once.
SessionVerdict press_the_rope(const std::string& name,
                              const std::vector<std::string>& server_arguments) {
  const fs::path dir = testing::scratch_directory(name);
  const fs::path shipped = fs::path(COHAPTIC_SOURCE_DIR) / "scenes/objects";
  for (const std::string user : {"a", "b"}) {
    std::ifstream script(shipped / "paired_boxes" / ("surgeon_" + user + ".yaml"));
    std::ofstream once(dir / (user + ".yaml"));
    for (std::string line; std::getline(script, line);)
      if (line.rfind("repeat:", 0) != 0) once << line << '\n';
  }
  return verdict_of(dir, shipped / "paired_boxes.yaml", server_arguments, {"a", "b"});
}

bool mentions(const std::vector<std::string>& lines, const std::string& text) {
  for (const std::string& line : lines)
    if (line.find(text) != std::string::npos) return true;
  return false;
}

// The fed session has no problem; the starved one is UNHEALTHY for its step rate and its
// stale IRs (`users` named), and for nothing else but what stale IRs do to a user: one
// whose IR is flagged as old may also be held at the force limit, its tool having gone on
// past where a fresh IR's body would have stopped it.
void expect_only_starvation(const SessionVerdict& fed, const SessionVerdict& starved,
                            const std::vector<std::string>& users) {
  EXPECT_TRUE(fed.problems.empty()) << fed.report["problems"].dump(1);
  EXPECT_TRUE(fed.report["healthy"].get<bool>());
  EXPECT_FALSE(starved.report["healthy"].get<bool>());
  EXPECT_TRUE(
      mentions(starved.problems, "Hz, below 90 % of its target 20 Hz: capped by --sim-rate-hz 2"))
      << starved.report["problems"].dump(1);
  for (const std::string& user : users)
    EXPECT_TRUE(mentions(starved.problems, user + ": IR age p99"))
        << starved.report["problems"].dump(1);
  for (const std::string& problem : starved.problems) {
    const std::string user = problem.substr(0, problem.find(':'));
    const bool stale_user_at_the_limit =
        problem.find("held at the force limit") != std::string::npos &&
        mentions(starved.problems, user + ": IR age p99");
    EXPECT_TRUE(problem.find("step") != std::string::npos ||
                problem.find("IR age") != std::string::npos ||
                problem.find("faded") != std::string::npos || stale_user_at_the_limit)
        << "a cause other than the starved server: " << problem;
  }
}

TEST(SessionHealth, AStarvedServerIsUnhealthyNamingItsStepRateAndTheSameSessionFedIsHealthy) {
  const SessionVerdict fed = press_the_cube("health-fed", {});
  if (HasFatalFailure()) return;
  const SessionVerdict starved = press_the_cube("health-starved", {"--sim-rate-hz", "2"});
  if (HasFatalFailure()) return;
  expect_only_starvation(fed, starved, {"a"});
}

TEST(SessionHealth, TheRopeOnTheBlockStarvedIsUnhealthyAndFedIsHealthy) {
  const SessionVerdict fed = press_the_rope("rope-fed", {});
  if (HasFatalFailure()) return;
  const SessionVerdict starved = press_the_rope("rope-starved", {"--sim-rate-hz", "2"});
  if (HasFatalFailure()) return;
  expect_only_starvation(fed, starved, {"a", "b"});
}

}  // namespace
}  // namespace cohaptic
