// CubeSession: an end-to-end test's session on loopback: a soft two-tool cube scene
// written to a scratch directory, a cohaptic-server process serving it (port 0, its report
// and log in the directory), and cohaptic-client processes with scripted presses.
#pragma once

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/process.h"

namespace cohaptic::testing {

/// A soft cube (forces well under the 3.3 N limit) with `tools` point tools (A, B, ..., at
/// most 4), touchable on its top face (z = 0 mm); `extra` is appended to the scene text
/// (e.g. a network section).
void write_cube_scene(const std::filesystem::path& dir, const std::string& extra = "",
                      int tools = 2);

/// Press `depth` mm at (x, y) mm, hold, release: about 0.4 + 2 * depth / 5 + hold seconds.
std::filesystem::path write_press(const std::filesystem::path& dir, const std::string& name,
                                  double x, double y, double depth, double hold);

/// The haptic period p99 [us] a well-behaved client keeps while others misbehave: its own
/// bare timer floor's p99 (measured beside its loop, so the machine's load is in both) and a
/// tenth, plus 150 us, and never less than 1.1 ms (a 1 kHz period and a tenth). The tenth is
/// for a host that stalls its vCPUs for milliseconds: two p99s of such a tail, each from a few
/// thousand periods, differ by that much with no fault of the loop's.
double period_p99_allowance_us(const nlohmann::json& client_report);

/// A client of the server at 127.0.0.1:`port` with a scripted device, its report, recording
/// and log in `dir` named after `user`; `slot` -1: the first free one.
std::unique_ptr<ChildProcess> scripted_client(const std::filesystem::path& dir, int port,
                                              const std::string& user, int slot,
                                              const std::filesystem::path& trajectory,
                                              const std::vector<std::string>& extra = {});

struct CubeSession {
  std::filesystem::path dir;
  std::unique_ptr<ChildProcess> server;
  int port = -1;
  /// Starts the server with `server_arguments` after the usual ones (a path after
  /// --display or --record is made the session directory's); waits until it listens.
  CubeSession(const std::string& name, const std::vector<std::string>& server_arguments,
              const std::string& scene_extra = "", int tools = 2);
  /// A client with a scripted device, its report, recording and log in the directory.
  std::unique_ptr<ChildProcess> client(const std::string& user, int slot,
                                       const std::filesystem::path& trajectory,
                                       const std::vector<std::string>& extra = {}) const;
  /// `name`.json of the directory.
  nlohmann::json report(const std::string& name) const;
  /// SIGINT, and the server must exit 0.
  void stop_server();
};

}  // namespace cohaptic::testing
