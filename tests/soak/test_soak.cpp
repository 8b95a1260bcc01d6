// The soak: hours of use compressed into a session with four participants and churn, under
// 10 % datagram loss and 10 ms jitter (injected by the server), for COHAPTIC_SOAK_MINUTES
// minutes (3 by default, as CI runs it; docs/security.md "Security and robustness" runs 60):
//   - alice and bob, real clients, press and slide on the cube for the whole run;
//   - carol, a real client, joins, presses and leaves, again and again: a new process, a
//     new report and a new recording every few seconds;
//   - dave, a hand-made participant (support/raw_participant.h), joins with a small receive
//     window and slides without ever reading his control connection, until the server drops
//     him for it; then he joins again, and again;
//   - erin sends garbage: 500 hostile datagrams a second (support/hostile_traffic.h), and
//     every few seconds a control connection carrying random bytes.
// Asserted: after warm-up (the first fifth, at least 30 s) the resident set of the server
// and of alice's and bob's clients grows by at most 5 %, and their file descriptors are as
// many at the end as at the start (the same participants connected); no client's haptic
// loop output a NaN; every recording (the server's, every client session's) reads and
// verifies clean (replay --verify); alice's and bob's haptic period p99 within their bare
// timer floor's allowance; every datagram alice, bob and carol sent accepted, every hostile
// datagram and connection rejected and counted; dave dropped every time (his IRs come as
// compliance rows, which must arrive: none is dropped before he is).
#include <gtest/gtest.h>
#include <signal.h>

#include <Eigen/Core>
#include <algorithm>
#include <asio.hpp>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "common/util/error.h"
#include "common/util/yaml_cursor.h"
#include "lab/replay.h"
#include "proto/record/recording.h"
#include "proto/wire/session_key.h"
#include "proto/wire/traffic_keys.h"
#include "support/cube_session.h"
#include "support/hostile_traffic.h"
#include "support/process.h"
#include "support/process_usage.h"
#include "support/raw_participant.h"

namespace cohaptic {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using testing::ChildProcess;
using testing::CubeSession;
using testing::ProcessUsage;

double soak_minutes() {
  const char* text = std::getenv("COHAPTIC_SOAK_MINUTES");
  if (!text) return 3;
  char* end = nullptr;
  const double minutes = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(minutes >= 1 && minutes <= 24 * 60))
    throw Error(
        fmt::format("COHAPTIC_SOAK_MINUTES='{}': a number of minutes from 1 to 1440", text));
  return minutes;
}

// A steady user's script, `seconds` long at least: from above (x, y) mm, press 3 mm, hold,
// slide 10 mm along x and back (new contact sets, new IRs), release; again and again.
fs::path write_steady_script(const fs::path& dir, const std::string& name, double x, double y,
                             double seconds) {
  const fs::path file = dir / (name + ".yaml");
  std::ofstream(file) << fmt::format(R"(
units: mm
start: [{0}, {1}, 6]
repeat: {2}
segments:
  - {{move_to: [{0}, {1}, 0.5], speed: 20}}
  - {{press: 3, speed: 5, direction: [0, 0, -1]}}
  - {{hold: 0.5}}
  - {{move_by: [10, 0, 0], speed: 10}}
  - {{move_by: [-10, 0, 0], speed: 10}}
  - {{release: 3, speed: 5}}
)",
                                     x, y, static_cast<int>(seconds / 3.5) + 2);
  return file;
}

// Dave's path: 2 mm deep, back and forth along x across the top face, a new IR at every triangle.
Eigen::Vector3d dave_slide(double t) {
  return {0.04 * std::sin(2 * M_PI * t / 3.0), 0.011, -0.002};
}

struct UsageSample {
  double t_s = 0;
  ProcessUsage usage;
};

// The largest resident set among the samples in [from_s, to_s).
std::size_t peak_rss(const std::vector<UsageSample>& samples, double from_s, double to_s) {
  std::size_t peak = 0;
  for (const UsageSample& s : samples)
    if (s.t_s >= from_s && s.t_s < to_s) peak = std::max(peak, s.usage.rss_bytes);
  return peak;
}

std::uint64_t at(const nlohmann::json& report, const std::vector<std::string>& path) {
  const nlohmann::json* node = &report;
  for (const std::string& key : path) node = &node->at(key);
  return node->get<std::uint64_t>();
}

TEST(Soak, FourParticipantsWithChurnAStalledReaderAndGarbageUnderLossAndJitter) {
  const double minutes = soak_minutes();
  const double run_s = minutes * 60;
  const double warm_up_s = std::max(30.0, run_s / 5);
  const double churn_s =
      run_s - 20;  // then 20 s with alice and bob alone, to compare with the start
  CubeSession session("soak",
                      {"--duration", fmt::format("{:.0f}", run_s + 120), "--loss", "0.1",
                       "--jitter-ms", "10", "--seed", "16", "--record", "server.mcap"},
                      "", 4);
  // alice and bob press until they are told to stop (their scripts last longer than the run).
  const auto alice =
      session.client("alice", 0, write_steady_script(session.dir, "a", -25, -30, run_s + 120));
  const auto bob =
      session.client("bob", 1, write_steady_script(session.dir, "b", 15, -30, run_s + 120));
  for (auto* client : {alice.get(), bob.get()})
    ASSERT_TRUE(testing::wait_for_output(*client, "haptic loop at"));
  const std::vector<std::pair<std::string, ChildProcess*>> watched = {
      {"server", session.server.get()}, {"alice", alice.get()}, {"bob", bob.get()}};
  const Clock::time_point start = Clock::now();
  const auto seconds_since_start = [&] {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  std::this_thread::sleep_for(2s);  // the first IRs are in
  std::map<std::string, ProcessUsage> before;
  for (const auto& [name, process] : watched)
    before[name] = testing::usage_of(process->pid()).value();

  std::atomic<bool> stop{false};
  // carol: a new client process every few seconds (join, press, leave).
  std::vector<std::string> carols;
  std::vector<int> carol_exits;
  const fs::path carol_script = testing::write_press(session.dir, "c", -20, 35, 2, 1.0);
  std::thread carol_thread([&] {
    while (!stop) {
      const std::string name = fmt::format("carol-{:03}", carols.size() + 1);
      const auto carol = session.client(name, 2, carol_script, {"--join-timeout", "20"});
      carols.push_back(name);
      const std::optional<int> status = carol->wait(testing::kPatience);
      carol_exits.push_back(status.value_or(-1));
      std::this_thread::sleep_for(500ms);  // stimulus: the slot stays empty a moment
    }
  });
  // dave: joins, slides without reading, is dropped; again.
  int dave_sessions = 0, dave_dropped = 0;
  std::vector<std::string> dave_failures;
  std::thread dave_thread([&] {
    while (!stop) {
      const std::string name = fmt::format("dave-{:03}", dave_sessions + 1);
      testing::RawParticipant dave({.server_port = static_cast<std::uint16_t>(session.port),
                                    .slot = 3,
                                    .name = name,
                                    .tcp_receive_buffer = 4096},
                                   wire::ClientKeys(wire::development_key()));
      try {
        dave.join(testing::kPatience);
      } catch (const Error& e) {
        dave_failures.push_back(e.what());
        std::this_thread::sleep_for(1s);
        continue;
      }
      ++dave_sessions;
      dave.press_along(dave_slide);
      const std::string dropped =
          fmt::format("user '{}' (slot 3) left: the peer stopped reading", name);
      while (!stop && session.server->log_text().find(dropped) == std::string::npos)
        std::this_thread::sleep_for(100ms);
      if (!stop) ++dave_dropped;
    }
  });
  // erin: hostile datagrams, 500 a second, and a control connection of random bytes every 3 s.
  std::uint64_t hostile_datagrams = 0, hostile_connections = 0;
  std::thread erin_datagrams([&] {
    asio::io_context io;
    asio::ip::udp::socket socket(io, asio::ip::udp::endpoint(asio::ip::udp::v4(), 0));
    const asio::ip::udp::endpoint server(asio::ip::make_address("127.0.0.1"),
                                         static_cast<std::uint16_t>(session.port));
    std::mt19937 rng(16);
    testing::HostileDatagrams hostile(testing::session_id(*session.server), rng);
    for (auto next = Clock::now(); !stop; next += 2ms) {
      socket.send_to(asio::buffer(hostile.next()), server);
      ++hostile_datagrams;
      std::this_thread::sleep_until(next);
    }
  });
  std::thread erin_connections([&] {
    asio::io_context io;
    std::mt19937 rng(61);
    while (!stop) {
      asio::ip::tcp::socket socket(io);
      socket.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"),
                                             static_cast<std::uint16_t>(session.port)));
      testing::Bytes garbage(64 + rng() % 2000);
      for (auto& byte : garbage) byte = static_cast<std::uint8_t>(rng());
      asio::write(socket, asio::buffer(garbage));
      ++hostile_connections;
      // Until the server closes it: at once (a rejected frame) or at its join timeout.
      std::array<std::uint8_t, 4096> sink{};
      std::error_code error;
      while (!error) socket.read_some(asio::buffer(sink), error);
      std::this_thread::sleep_for(3s);
    }
  });

  // Sample everyone's usage once a second until the churn ends.
  std::map<std::string, std::vector<UsageSample>> usage;
  while (seconds_since_start() < churn_s) {
    for (const auto& [name, process] : watched)
      if (const auto now = testing::usage_of(process->pid()))
        usage[name].push_back({seconds_since_start(), *now});
    std::this_thread::sleep_for(1s);
  }
  stop = true;
  for (std::thread* t : {&carol_thread, &dave_thread, &erin_datagrams, &erin_connections})
    t->join();
  std::this_thread::sleep_for(3s);  // stimulus: the last leavers' connections close
  std::map<std::string, ProcessUsage> after;
  for (const auto& [name, process] : watched)
    after[name] = testing::usage_of(process->pid()).value();
  for (auto* client : {alice.get(), bob.get()}) client->signal(SIGINT);
  for (auto* client : {alice.get(), bob.get()})
    ASSERT_EQ(client->wait(testing::kPatience), 0) << client->log_text();
  session.stop_server();

  // Memory and descriptors.
  std::printf(
      "  soak of %g min (warm-up %.0f s): carol joined %zu times, dave %d (dropped %d), erin sent "
      "%lu hostile "
      "datagrams and %lu hostile connections\n",
      minutes, warm_up_s, carols.size(), dave_sessions, dave_dropped,
      static_cast<unsigned long>(hostile_datagrams),
      static_cast<unsigned long>(hostile_connections));
  for (const auto& [name, process] : watched) {
    const std::vector<UsageSample>& samples = usage[name];
    const std::size_t warm = peak_rss(samples, warm_up_s - 10, warm_up_s);
    const std::size_t last = peak_rss(samples, churn_s - 10, churn_s);
    const double growth = static_cast<double>(last) / static_cast<double>(warm) - 1;
    std::printf(
        "  %-6s RSS %.1f MB at the start, %.1f MB after warm-up, %.1f MB at the end (%+.2f %%); "
        "fds %zu at the "
        "start, %zu at the end\n",
        name.c_str(), static_cast<double>(before[name].rss_bytes) / 1e6,
        static_cast<double>(warm) / 1e6, static_cast<double>(last) / 1e6, 100 * growth,
        before[name].open_fds, after[name].open_fds);
    EXPECT_GT(warm, 0u) << name;
    EXPECT_LE(growth, 0.05) << name << "'s resident set grew after warm-up";
    EXPECT_EQ(after[name].open_fds, before[name].open_fds) << name << "'s file descriptors";
  }

  // The haptic loops.
  std::uint64_t legitimate_sent = 0;
  for (const std::string& name : {std::string("alice"), std::string("bob")}) {
    const nlohmann::json report = session.report(name);
    legitimate_sent += at(report, {"datagrams", "sent"});
    std::printf(
        "  %-6s haptic period p99 %.0f us (timer floor p99 %.0f us), %lu ticks, %lu IRs received\n",
        name.c_str(), report["period_us"]["p99"].get<double>(),
        report["timer_floor"]["period_us"]["p99"].get<double>(),
        static_cast<unsigned long>(at(report, {"ticks"})),
        static_cast<unsigned long>(at(report, {"ir", "received"})));
    EXPECT_LE(report["period_us"]["p99"].get<double>(), testing::period_p99_allowance_us(report))
        << name;
    EXPECT_EQ(report["non_finite_ticks"], 0) << name;
  }
  ASSERT_EQ(carol_exits.size(), carols.size());
  for (std::size_t i = 0; i < carols.size(); ++i) {
    EXPECT_EQ(carol_exits[i], 0) << carols[i] << ": "
                                 << read_text_file((session.dir / (carols[i] + ".log")).string());
    if (carol_exits[i] != 0) continue;
    const nlohmann::json report = session.report(carols[i]);
    legitimate_sent += at(report, {"datagrams", "sent"});
    EXPECT_EQ(report["non_finite_ticks"], 0) << carols[i];
  }
  EXPECT_GE(carols.size(), static_cast<std::size_t>(churn_s / 10))
      << "carol came and went every few seconds";

  // The server: the stalled reader, the garbage, the legitimate samples.
  const nlohmann::json server = session.report("server")["server"];
  std::printf(
      "  server: %lu datagrams accepted, %lu rejected (%lu rate-limited), %lu frames rejected, %lu "
      "join timeouts, "
      "%lu write stalls, %lu queue overflows, %lu frames dropped unsent; failed steps %lu\n",
      static_cast<unsigned long>(at(server, {"datagrams", "accepted"})),
      static_cast<unsigned long>(at(server, {"datagrams", "rejected"})),
      static_cast<unsigned long>(at(server, {"datagrams", "rejected_by_reason", "rate_limited"})),
      static_cast<unsigned long>(at(server, {"control_frames", "rejected"})),
      static_cast<unsigned long>(at(server, {"connections", "join_timeouts"})),
      static_cast<unsigned long>(at(server, {"connections", "write_stalls"})),
      static_cast<unsigned long>(at(server, {"connections", "queue_overflows"})),
      static_cast<unsigned long>(at(server, {"control_frames", "dropped"})),
      static_cast<unsigned long>(at(server, {"failed_steps", "count"})));
  EXPECT_TRUE(dave_failures.empty()) << dave_failures.front();
  EXPECT_GE(dave_dropped, dave_sessions - 1) << "dave is dropped every time he stops reading";
  EXPECT_GE(dave_dropped, 2);
  EXPECT_EQ(
      at(server, {"connections", "write_stalls"}) + at(server, {"connections", "queue_overflows"}),
      static_cast<std::uint64_t>(dave_dropped));
  EXPECT_EQ(at(server, {"control_frames", "dropped"}), 0u)
      << "dave's IRs (compliance rows, which must arrive): none is dropped before he is";
  EXPECT_EQ(
      at(server, {"control_frames", "rejected"}) + at(server, {"connections", "join_timeouts"}),
      hostile_connections)
      << server["control_frames"].dump();
  EXPECT_GE(at(server, {"datagrams", "rejected"}), hostile_datagrams * 99 / 100)
      << server["datagrams"].dump();
  EXPECT_GE(at(server, {"datagrams", "accepted"}), legitimate_sent)
      << "a legitimate datagram was lost or refused";
  EXPECT_EQ(at(server, {"failed_steps", "count"}), 0u);

  // Every recording reads and verifies.
  std::vector<std::string> recordings = {"server", "alice", "bob"};
  for (std::size_t i = 0; i < carols.size(); ++i)
    if (carol_exits[i] == 0) recordings.push_back(carols[i]);
  std::size_t checked = 0;
  for (const std::string& name : recordings) {
    const VerifyResult result = verify_recording(session.dir / (name + ".mcap"));
    EXPECT_TRUE(result.ok) << name << ".mcap: " << result.first_difference;
    EXPECT_GT(result.checked, 0u) << name << ".mcap";
    checked += result.checked;
  }
  std::printf("  %zu recordings verified: %zu forces and IRs recomputed bit for bit\n",
              recordings.size(), checked);
}

}  // namespace
}  // namespace cohaptic
