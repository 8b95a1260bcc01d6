// The session needs no browser: a server asked for a live view it cannot serve (its port
// taken by another program) says once that the view is off and why, and the session goes on.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "support/cube_scene.h"
#include "support/process.h"
#include "support/taken_port.h"

namespace cohaptic {
namespace {

namespace fs = std::filesystem;

TEST(LiveView, AViewThatCannotServeItsPageIsOffAndTheSessionGoesOn) {
  const testing::TakenPort taken;
  ASSERT_GT(taken.port(), 0);
  const fs::path dir = testing::scratch_directory("view-off");
  testing::CubeSceneOptions cube;
  cube.divisions = 4;
  cube.tools = "[{name: A}]";
  std::ofstream(dir / "cube.yaml") << testing::cube_scene_yaml(cube);
  std::ofstream(dir / "a.yaml") << "units: mm\nstart: [0, 0, 80]\nsegments:\n  - {hold: 1}\n";

  testing::run_scripted_session(dir, dir / "cube.yaml",
                                {"--view", "127.0.0.1:" + std::to_string(taken.port())},
                                {{"a", dir / "a.yaml"}});
  std::ifstream in(dir / "server.log");
  const std::string log((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string off =
      "live view off: view: cannot listen on 127.0.0.1:" + std::to_string(taken.port());
  EXPECT_NE(log.find(off), std::string::npos) << log;
  EXPECT_EQ(log.find("live view off"), log.rfind("live view off")) << "said once\n" << log;
  EXPECT_EQ(log.find("live view at"), std::string::npos) << log;
  EXPECT_TRUE(fs::exists(dir / "a.json")) << "the client's session ran to its end";
}

}  // namespace
}  // namespace cohaptic
