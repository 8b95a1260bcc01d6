#include "support/cube_session.h"

#include <fmt/format.h>
#include <signal.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>

namespace cohaptic::testing {

namespace fs = std::filesystem;

void write_cube_scene(const fs::path& dir, const std::string& extra, int tools) {
  if (tools < 1 || tools > 4)
    throw std::invalid_argument(fmt::format("write_cube_scene: {} tools, not 1 to 4", tools));
  std::string tool_list;
  for (int k = 0; k < tools; ++k)
    tool_list += fmt::format("{}{{name: {}}}", k ? ", " : "", static_cast<char>('A' + k));
  std::ofstream(dir / "cube.yaml") << R"(
name: soft-cube
units: mm
objects:
  - name: cube
    mesh: {box: {min: [-65, -65, -130], size: [130, 130, 130], divisions: [8, 8, 8]}}
    material: {youngs_modulus: 2.0e4, poisson_ratio: 0.4}
    fixed: [{plane: {point: [0, 0, -130], normal: [0, 0, 1]}}]
    touchable: [{plane: {point: [0, 0, 0], normal: [0, 0, 1]}}]
    compliance: {precompute: touchable, disk_cache: false}
tools: [)" << tool_list << R"(]
haptic: {rate_hz: 1000, force_limit: 3.3, contact_model: translation, patch_rings: 1}
)" << extra;
}

fs::path write_press(const fs::path& dir, const std::string& name, double x, double y, double depth,
                     double hold) {
  const fs::path file = dir / (name + ".yaml");
  std::ofstream(file) << fmt::format(R"(
units: mm
start: [{0}, {1}, 6]
segments:
  - {{move_to: [{0}, {1}, 0.5], speed: 20}}
  - {{press: {2}, speed: 5, direction: [0, 0, -1]}}
  - {{hold: {3}}}
  - {{release: {2}, speed: 5}}
)",
                                     x, y, depth, hold);
  return file;
}

double period_p99_allowance_us(const nlohmann::json& client_report) {
  const double floor_p99 = client_report.at("timer_floor").at("period_us").at("p99").get<double>();
  return std::max(1100.0, 1.1 * floor_p99 + 150);
}

CubeSession::CubeSession(const std::string& name, const std::vector<std::string>& server_arguments,
                         const std::string& scene_extra, int tools)
    : dir(scratch_directory(name)) {
  write_cube_scene(dir, scene_extra, tools);
  std::vector<std::string> arguments = {
      "--scene",  (dir / "cube.yaml").string(),   "--listen",       "127.0.0.1:0",
      "--report", (dir / "server.json").string(), "--no-disk-cache"};
  for (const std::string& argument :
       server_arguments) {  // paths after --display and --record are the session directory's
    const bool in_directory = arguments.back() == "--display" || arguments.back() == "--record";
    arguments.push_back(in_directory ? (dir / argument).string() : argument);
  }
  server = std::make_unique<ChildProcess>(server_program(), arguments, dir / "server.log");
  EXPECT_TRUE(wait_for_output(*server, "listening on"));
  port = listening_port(server->log_text());
}

std::unique_ptr<ChildProcess> CubeSession::client(const std::string& user, int slot,
                                                  const fs::path& trajectory,
                                                  const std::vector<std::string>& extra) const {
  return scripted_client(dir, port, user, slot, trajectory, extra);
}

std::unique_ptr<ChildProcess> scripted_client(const fs::path& dir, int port,
                                              const std::string& user, int slot,
                                              const fs::path& trajectory,
                                              const std::vector<std::string>& extra) {
  std::vector<std::string> arguments = {
      "--server", fmt::format("127.0.0.1:{}", port), "--user",   user,
      "--device", "script:" + trajectory.string(),   "--report", (dir / (user + ".json")).string(),
      "--record", (dir / (user + ".mcap")).string()};
  if (slot >= 0) arguments.insert(arguments.end(), {"--slot", std::to_string(slot)});
  arguments.insert(arguments.end(), extra.begin(), extra.end());
  return std::make_unique<ChildProcess>(client_program(), arguments, dir / (user + ".log"));
}

nlohmann::json CubeSession::report(const std::string& name) const {
  std::ifstream in(dir / (name + ".json"));
  return nlohmann::json::parse(in);
}

void CubeSession::stop_server() {
  server->signal(SIGINT);
  EXPECT_EQ(server->wait(kPatience), 0) << server->log_text();
}

}  // namespace cohaptic::testing
