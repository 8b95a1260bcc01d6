// What a user is told when a client cannot start (end to end, the real client program): a
// bad device file is named before the client tries to join anyone; a server that is not
// there and one that rejects the key are different messages; a tool whose path stays far
// from the scene (a file in metres read as millimetres' worth, say) is warned of at start.
#include <gtest/gtest.h>

#include <signal.h>

#include <fmt/format.h>

#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "proto/wire/session_key.h"
#include "support/cube_scene.h"
#include "support/process.h"
#include "support/taken_port.h"

namespace cohaptic {
namespace {
namespace fs = std::filesystem;
using namespace std::chrono_literals;

// The client's log once it has ended (it must end within the patience).
std::string client_log(const fs::path& dir, const std::string& name,
                       std::vector<std::string> arguments) {
  testing::ChildProcess client(testing::client_program(), arguments, dir / (name + ".log"));
  const std::optional<int> status = client.wait(testing::kPatience);
  EXPECT_TRUE(status.has_value()) << name;
  return client.log_text();
}

std::string write_hold(const fs::path& dir, const std::string& name, const std::string& units) {
  const fs::path file = dir / (name + ".yaml");
  std::ofstream(file) << fmt::format(
      "units: {}\nstart: [10, 10, 5]\nsegments:\n  - {{hold: 0.5}}\n", units);
  return file.string();
}

TEST(ClientStart, ABadDeviceFileIsNamedBeforeJoining) {
  const fs::path dir = testing::scratch_directory("client-bad-device");
  const std::string log =
      client_log(dir, "client",
                 {"--server", fmt::format("127.0.0.1:{}", testing::closed_port()), "--user", "a",
                  "--device", "script:" + (dir / "missing.yaml").string()});
  EXPECT_NE(log.find("missing.yaml: cannot open the file"), std::string::npos) << log;
  EXPECT_EQ(log.find("cannot join"), std::string::npos) << "it tried to join first\n" << log;
}

TEST(ClientStart, NobodyListeningAndARejectedKeyAreDifferentMessagesAndAFarPathIsWarned) {
  const fs::path dir = testing::scratch_directory("client-start");
  const std::string hold = write_hold(dir, "hold", "mm");
  std::string log =
      client_log(dir, "refused",
                 {"--server", fmt::format("127.0.0.1:{}", testing::closed_port()), "--user", "a",
                  "--device", "script:" + hold, "--join-timeout", "2"});
  EXPECT_NE(log.find("connection refused: nothing listens there"), std::string::npos) << log;

  wire::write_session_key(dir / "server.key");
  wire::write_session_key(dir / "other.key");
  testing::CubeSceneOptions cube;
  cube.divisions = 4;
  std::ofstream(dir / "cube.yaml") << testing::cube_scene_yaml(cube);
  testing::ChildProcess server(testing::server_program(),
                               {"--scene", (dir / "cube.yaml").string(), "--listen", "127.0.0.1:0",
                                "--key-file", (dir / "server.key").string(), "--duration", "60"},
                               dir / "server.log");
  ASSERT_TRUE(testing::wait_for_output(server, "listening on")) << server.log_text();
  const std::string address =
      fmt::format("127.0.0.1:{}", testing::listening_port(server.log_text()));
  log = client_log(dir, "rejected",
                   {"--server", address, "--user", "a", "--device", "script:" + hold, "--key-file",
                    (dir / "other.key").string(), "--join-timeout", "3"});
  EXPECT_NE(log.find("the server rejected the key"), std::string::npos) << log;
  EXPECT_EQ(log.find("connection refused"), std::string::npos) << log;

  // The same hold with its numbers read as metres: 10 m away from a 130 mm cube.
  log = client_log(
      dir, "far",
      {"--server", address, "--user", "a", "--device", "script:" + write_hold(dir, "far", "m"),
       "--key-file", (dir / "server.key").string(), "--duration", "0.5"});
  EXPECT_NE(log.find("stays 14.9 m or more from the scene"), std::string::npos)
      << log;  // |(9.935, 9.935, 5)| m
  EXPECT_NE(log.find("it will touch nothing (is the file's unit right?"), std::string::npos) << log;
  log = client_log(dir, "near",
                   {"--server", address, "--user", "a", "--device", "script:" + hold, "--key-file",
                    (dir / "server.key").string(), "--duration", "0.5"});
  EXPECT_EQ(log.find("it will touch nothing"), std::string::npos) << log;
  server.signal(SIGINT);
  EXPECT_EQ(server.wait(testing::kPatience), 0) << server.log_text();
}

}  // namespace
}  // namespace cohaptic
