// Replay of recorded sessions with the real programs: a two-user session's three recordings
// verify bit for bit; a changed value is found and named; a client killed mid-session
// leaves a recording that reads (and verifies) up to its last complete chunk, every message
// checked by its chunk's CRC.
#include <gtest/gtest.h>
#include <signal.h>

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "client/device/make_device.h"
#include "client/device/recorded_motion.h"
#include "common/util/error.h"
#include "lab/replay.h"
#include "proto/record/recording.h"
#include "proto/record/session_recorder.h"
#include "proto/wire/vec3_convert.h"
#include "support/cube_scene.h"
#include "support/process.h"
#include "support/run_program.h"

namespace cohaptic {
namespace {

namespace fs = std::filesystem;
using testing::ChildProcess;

// `truncation`: the scene's haptic boundary_truncation.
void write_files(const fs::path& dir, double truncation) {
  testing::CubeSceneOptions soft;  // forces well under the 3.3 N limit
  soft.divisions = 8;
  soft.youngs_modulus = 2.0e4;
  soft.touchable = "{surface: true}";
  std::string scene = testing::cube_scene_yaml(soft);
  if (truncation > 0)
    scene.replace(scene.find("haptic: {"), 9,
                  fmt::format("haptic: {{boundary_truncation: {}, ", truncation));
  std::ofstream(dir / "cube.yaml") << scene;
  for (const auto& [name, x] : {std::pair{"a", -20}, std::pair{"b", 20}})
    std::ofstream(dir / (std::string(name) + ".yaml")) << fmt::format(R"(
units: mm
start: [{0}, 2, 6]
segments:
  - {{move_to: [{0}, 2, 0.5], speed: 20}}
  - {{press: 4, speed: 5, direction: [0, 0, -1]}}
  - {{move_by: [8, 0, 0], speed: 8}}
  - {{release: 4, speed: 5}}
)",
                                                                      x);
}

struct RecordedSession {
  fs::path dir;
  explicit RecordedSession(const std::string& name,
                           const std::vector<std::string>& server_extra = {}, double truncation = 0)
      : dir(testing::scratch_directory(name)) {
    write_files(dir, truncation);
    std::vector<std::string> args = {"--scene",        (dir / "cube.yaml").string(),
                                     "--listen",       "127.0.0.1:0",
                                     "--duration",     "30",
                                     "--record",       (dir / "server.mcap").string(),
                                     "--step-nodes",   "40",
                                     "--no-disk-cache"};
    args.insert(args.end(), server_extra.begin(), server_extra.end());
    server = std::make_unique<ChildProcess>(testing::server_program(), args, dir / "server.log");
    EXPECT_TRUE(testing::wait_for_output(*server, "listening on"));
    port = testing::listening_port(server->log_text());
  }
  // A client playing `device` (default: the user's script), recording to <user>.mcap.
  std::unique_ptr<ChildProcess> client(const std::string& user, int slot,
                                       const std::string& device = "") const {
    return std::make_unique<ChildProcess>(
        testing::client_program(),
        std::vector<std::string>{
            "--server", fmt::format("127.0.0.1:{}", port), "--user", user, "--slot",
            std::to_string(slot), "--device",
            device.empty() ? "script:" + (dir / (user + ".yaml")).string() : device, "--record",
            (dir / (user + ".mcap")).string(), "--report", (dir / (user + ".json")).string()},
        dir / (user + ".log"));
  }
  void stop() {
    server->signal(SIGINT);
    EXPECT_EQ(server->wait(testing::kPatience), 0) << server->log_text();
  }
  // One user's session: its client in slot 0 runs its script to the end, then the server stops.
  void run_one_user(const std::string& user) {
    const auto c = client(user, 0);
    EXPECT_EQ(c->wait(testing::kPatience), 0) << c->log_text();
    stop();
  }
  std::unique_ptr<ChildProcess> server;
  int port = -1;
};

TEST(Replay, ATwoUserSessionVerifiesBitForBit) {
  RecordedSession session("replay-two", {"--protocol", "P1"});
  const auto a = session.client("a", 0);
  const auto b = session.client("b", 1);
  ASSERT_EQ(a->wait(testing::kPatience), 0) << a->log_text();
  ASSERT_EQ(b->wait(testing::kPatience), 0) << b->log_text();
  session.stop();
  for (const char* file : {"server.mcap", "a.mcap", "b.mcap"}) {
    const VerifyResult result = verify_recording(session.dir / file);
    EXPECT_TRUE(result.ok) << file << ": " << result.first_difference;
    EXPECT_GT(result.checked, 3u) << file;
    std::printf("  %s: %zu values re-run, identical\n", file, result.checked);
  }
  // Both users' forces were recorded with the other tool in them.
  const record::Recording a_recording = record::read_recording(session.dir / "a.mcap");
  bool saw_remote = false;
  for (const auto& tick : a_recording.ticks)
    saw_remote |= tick.remotes_size() > 0 && std::isfinite(tick.remotes(0).x());
  EXPECT_TRUE(saw_remote);
  EXPECT_FALSE(a_recording.truncated);

  // The summary of a client's recording shows its report's counters, recomputed from the ticks.
  for (const std::string user : {"a", "b"}) {
    ChildProcess replay(COHAPTIC_LAB_EXE,
                        {"replay", (session.dir / (user + ".mcap")).string(), "--summary"},
                        session.dir / ("summary-" + user + ".log"));
    ASSERT_EQ(replay.wait(testing::kPatience), 0) << replay.log_text();
    const std::string summary = replay.log_text();
    const nlohmann::json report =
        nlohmann::json::parse(std::ifstream(session.dir / (user + ".json")));
    std::smatch fades, ages;
    ASSERT_TRUE(std::regex_search(summary, fades, std::regex(R"(fades +(\d+) while pushing)")))
        << summary;
    EXPECT_EQ(std::stoi(fades[1].str()), report["fades"]["count"].get<int>()) << summary;
    ASSERT_TRUE(std::regex_search(
        summary, ages,
        std::regex(R"(IR age +p50 ([0-9.]+) ms, p99 ([0-9.]+) ms, max ([0-9.]+) ms)")))
        << summary;
    EXPECT_NEAR(std::stod(ages[2].str()), report["ir_age_ms"]["p99"].get<double>(), 0.051)
        << summary;
    EXPECT_NEAR(std::stod(ages[3].str()), report["ir_age_ms"]["max"].get<double>(), 0.051)
        << summary;
    EXPECT_GT(report["ir_age_ms"]["max"].get<double>(), 0)
        << "an IR age the summary could match by accident";
  }
}

// With B truncation the client receives compliance rows that list the held nodes left out;
// its recording keeps them as they came, and the replay completes them again, bit for bit.
TEST(Replay, ASessionWithBTruncationVerifiesBitForBit) {
  RecordedSession session("replay-truncation", {"--protocol", "P1"}, 0.2);
  session.run_one_user("a");
  const record::Recording a_recording = record::read_recording(session.dir / "a.mcap");
  std::size_t truncating = 0;
  for (const record::RecordedIr& ir : a_recording.irs)
    truncating += ir.ir().fem().truncated_node_ids_size() > 0;
  EXPECT_GT(truncating, 0u) << "no IR left a held node out";
  for (const char* file : {"server.mcap", "a.mcap"}) {
    const VerifyResult result = verify_recording(session.dir / file);
    EXPECT_TRUE(result.ok) << file << ": " << result.first_difference;
    EXPECT_GT(result.checked, 3u) << file;
    std::printf("  %s: %zu values re-run, identical (%zu IRs with truncated held nodes)\n", file,
                result.checked, truncating);
  }
}

TEST(Replay, AChangedForceIsFoundAndNamed) {
  RecordedSession session("replay-tamper", {"--protocol", "P1"});
  session.run_one_user("a");
  // Copy the client's recording with one output force one ulp off.
  const record::Recording original = record::read_recording(session.dir / "a.mcap");
  std::size_t changed = 0;
  {
    record::SessionRecorder copy(session.dir / "tampered.mcap");
    copy.config(original.config);
    for (const auto& d : original.datagrams) copy.datagram_in(d.receive_time_ns(), d.datagram());
    for (const auto& r : original.irs) copy.ir(r.time_ns(), r.ir());
    for (std::size_t i = 0; i < original.ticks.size(); ++i) {
      record::HapticTick tick = original.ticks[i];
      if (changed == 0 && tick.force().z() != 0 && i > 100) {
        tick.mutable_force()->set_z(std::nextafter(tick.force().z(), 1e9));
        changed = i;
      }
      copy.tick(tick);
    }
  }
  ASSERT_GT(changed, 0u);
  const VerifyResult result = verify_recording(session.dir / "tampered.mcap");
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.first_difference.find(fmt::format("haptic tick {} ", changed)),
            std::string::npos)
      << result.first_difference;
  EXPECT_NE(result.first_difference.find("output force"), std::string::npos)
      << result.first_difference;
}

TEST(Replay, AClientKilledMidSessionLeavesARecordingThatReadsAndVerifies) {
  RecordedSession session("replay-killed");
  // A press, then a slide far slower than the test waits for, so the kill comes mid-session.
  std::ofstream(session.dir / "hold.yaml") << R"(
units: mm
start: [-20, 2, 6]
segments:
  - {move_to: [-20, 2, 0.5], speed: 20}
  - {press: 4, speed: 5, direction: [0, 0, -1]}
  - {move_by: [8, 0, 0], speed: 0.1}
)";
  const auto a = session.client("a", 0, "script:" + (session.dir / "hold.yaml").string());
  // The recorder flushes while the session runs (at least every 100 ms), not only at the
  // end: a second's ticks reach the disk while the client is still running.
  std::size_t on_disk_before_kill = 0;
  ASSERT_TRUE(testing::wait_until(
      [&] {
        try {
          on_disk_before_kill = record::read_recording(session.dir / "a.mcap").ticks.size();
        } catch (const Error&) {  // not yet flushed
        }
        return on_disk_before_kill > 1000;
      },
      "more than 1000 haptic ticks flushed to the running client's recording"))
      << a->log_text();
  a->signal(SIGKILL);
  ASSERT_EQ(a->wait(testing::kPatience), 128 + SIGKILL);
  session.stop();
  const record::Recording recording = record::read_recording(session.dir / "a.mcap");
  EXPECT_TRUE(recording.truncated) << "a killed writer cannot have written the footer";
  EXPECT_GE(recording.ticks.size(), on_disk_before_kill)
      << "every tick flushed before the kill is still readable";
  const VerifyResult result = verify_recording(session.dir / "a.mcap");
  EXPECT_TRUE(result.ok) << result.first_difference;
  // Every message read lies in a chunk whose CRC matched, and replay says so.
  EXPECT_GT(recording.crc.checked_messages, recording.ticks.size());
  EXPECT_EQ(recording.crc.unchecked_messages, 0u);
  ASSERT_TRUE(recording.crc.checked_end_time_ns.has_value());
  EXPECT_GE(*recording.crc.checked_end_time_ns,
            static_cast<std::uint64_t>(recording.ticks.back().time_ns()));
  const testing::ProgramRun replay = testing::run_program(
      COHAPTIC_LAB_EXE, "replay '" + (session.dir / "a.mcap").string() + "' --verify");
  EXPECT_EQ(replay.exit_code, 0) << replay.out;
  const std::string line = record::describe_cut(recording);
  EXPECT_NE(line.find(fmt::format("cut short at byte {}: everything up to t = ",
                                  fs::file_size(session.dir / "a.mcap"))),
            std::string::npos)
      << line;
  EXPECT_NE(line.find(" s is checked by its chunks' CRCs"), std::string::npos) << line;
  EXPECT_NE(replay.out.find("verify: " + line + "\n"), std::string::npos) << replay.out;
  std::printf("  killed with %zu ticks on disk: %zu ticks readable (%s), all verified; %s\n",
              on_disk_before_kill, recording.ticks.size(), recording.truncation.c_str(),
              line.c_str());
}

// The deepest point (smallest z) of the own tool and the peak force of a client recording.
std::pair<double, double> deepest_and_peak(const record::Recording& recording) {
  double deepest = 1e9, peak = 0;
  for (const auto& tick : recording.ticks) {
    if (tick.own_valid()) deepest = std::min(deepest, tick.own().z());
    peak = std::max(peak, wire::from_wire(tick.force()).norm());
  }
  return {deepest, peak};
}

TEST(Replay, ARecordedHandMotionDrivesANewSession) {
  RecordedSession first("replay-motion-source", {"--protocol", "P1"});
  first.run_one_user("a");
  const record::Recording source = record::read_recording(first.dir / "a.mcap");

  // From a client recording: the own positions, from t = 0 at the first valid one.
  const Trajectory motion = recorded_motion(first.dir / "a.mcap", "");
  EXPECT_EQ(motion.knot_times().front(), 0.0);
  const auto& last_tick = source.ticks.back();
  EXPECT_EQ(motion.knot_points().back(), wire::from_wire(last_tick.own()));
  EXPECT_GT(motion.knot_times().size(), source.ticks.size() / 2);
  // From the server's recording: the positions the server used for slot 0, the same path.
  // (Its last point may be a sample older than the client's last: the final samples can
  // still be in flight when the client leaves. The depth, held during the slide, is there.)
  const Trajectory served = recorded_motion(first.dir / "server.mcap", "0");
  const auto lowest = [](const Trajectory& path) {
    double z = 1e9;
    for (const Eigen::Vector3d& p : path.knot_points()) z = std::min(z, p.z());
    return z;
  };
  EXPECT_NEAR(lowest(served), lowest(motion), 1e-12);
  EXPECT_NEAR(lowest(motion), -0.0035, 1e-9);
  // By the name the user joined with, too; an unknown name lists the users there were.
  const Trajectory by_name = recorded_motion(first.dir / "server.mcap", "a");
  EXPECT_EQ(by_name.knot_points().back(), served.knot_points().back());
  try {
    recorded_motion(first.dir / "server.mcap", "nobody");
    ADD_FAILURE() << "no error for an unknown user";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'a' (slot 0)"), std::string::npos) << e.what();
  }
  // The device spec splits FILE from USER at the last ':'.
  const auto device = make_device("replay:" + (first.dir / "server.mcap").string() + ":a", 3.0);
  EXPECT_NE(device->describe().find("server.mcap"), std::string::npos) << device->describe();
  EXPECT_THROW(make_device("replay:" + (first.dir / "server.mcap").string() + ":nobody", 3.0),
               Error);
  EXPECT_THROW(recorded_motion(first.dir / "server.mcap", "1"), Error) << "slot 1 never had a tool";

  // A new session driven by the recorded motion (open loop) reaches the same depth and
  // feels the same peak force.
  RecordedSession second("replay-motion-target", {"--protocol", "P1"});
  const auto replayed = second.client("r", 0, "replay:" + (first.dir / "a.mcap").string());
  ASSERT_EQ(replayed->wait(testing::kPatience), 0) << replayed->log_text();
  second.stop();
  const auto [source_depth, source_peak] = deepest_and_peak(source);
  const auto [replay_depth, replay_peak] =
      deepest_and_peak(record::read_recording(second.dir / "r.mcap"));
  std::printf("  deepest z %.4f mm vs %.4f mm; peak force %.4f N vs %.4f N\n", source_depth * 1e3,
              replay_depth * 1e3, source_peak, replay_peak);
  EXPECT_NEAR(replay_depth, source_depth, 2e-6);
  EXPECT_NEAR(replay_peak, source_peak, 0.02 * source_peak);
  EXPECT_GT(source_peak, 0.05);
}

}  // namespace
}  // namespace cohaptic
