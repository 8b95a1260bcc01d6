// cohaptic_attacks (`make attacks`): what an attacker on the network can try, replayed against
// a running server on loopback, while legitimate clients use it. It starts cohaptic-server on
// a three-tool cube with the live view (limited to 256 file descriptors, so that running out
// of them is cheap to reach), and alice, a real client that presses and holds for the whole
// run. Then each attack in turn, for a few seconds; during each, bob, another real client,
// joins, presses and leaves (after the file-descriptor attack, and after alice's link
// drops, alice joins again). Throughout, the server's resident set is sampled.
//
// It prints a Markdown page (docs/results/attacks.md): a row per attack (what was sent, what
// the server did, whether bob joined), what alice felt, what the server counted, and a
// verdict; it exits 1 if a legitimate client could not join or lost its
// haptic rate (missed more deadlines than the bare timer beside it, plus 0.1 % of its ticks:
// what the host's own scheduling takes from both is not the attacks'), the server's resident
// set passed 200 MB, or a file outside a recording's folder was read. Loopback only: it binds
// 127.0.0.0/8 addresses and talks to 127.0.0.1.
#include <signal.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fmt/format.h>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <random>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "common/util/error.h"
#include "lab/replay.h"
#include "lab/session_summary.h"
#include "proto/record/session_recorder.h"
#include "proto/wire/frame_codec.h"
#include "proto/wire/header.h"
#include "proto/wire/traffic_keys.h"
#include "support/cube_scene.h"
#include "support/cube_session.h"
#include "support/hostile_traffic.h"
#include "support/mcap_layout.h"
#include "support/process.h"
#include "support/process_usage.h"
#include "support/raw_participant.h"
#include "support/unjoined_connections.h"
#include "support/websocket_client.h"

namespace cohaptic {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using asio::ip::tcp;
using asio::ip::udp;
using Clock = std::chrono::steady_clock;

constexpr auto kAttackTime = 6s;
constexpr double kMaxServerRssMb = 200;

struct Target {
  fs::path dir;
  std::uint16_t port = 0, view_port = 0;
  std::uint64_t session = 0;
  tcp::endpoint control() const { return {asio::ip::make_address("127.0.0.1"), port}; }
  udp::endpoint datagrams() const { return {asio::ip::make_address("127.0.0.1"), port}; }
};

// bob, a real client in slot 1, joins, presses for half a second and leaves; the wait for
// his welcome, or a reason he did not get one.
std::string bob_joins(const Target& target, const std::string& run) {
  const auto started = Clock::now();
  const auto bob =
      testing::scripted_client(target.dir, target.port, "bob-" + run, 1,
                               testing::write_press(target.dir, "b-" + run, -40, -30, 2, 0.5));
  if (!testing::wait_for_output(*bob, "haptic loop at", 20s))
    return "bob did not join: " + bob->log_text();
  const double seconds = std::chrono::duration<double>(Clock::now() - started).count();
  if (bob->wait(testing::kPatience) != 0) return "bob's client failed: " + bob->log_text();
  return fmt::format("bob joined in {:.2f} s", seconds);
}

// Runs `attack` on its own thread for kAttackTime while bob joins.
std::string during(const Target& target, const std::string& run,
                   const std::function<std::string(Clock::time_point)>& attack) {
  const auto until = Clock::now() + kAttackTime;
  std::string what;
  std::thread attacker([&] {
    try {
      what = attack(until);
    } catch (const std::exception& error) {
      what = std::string("the attack could not be made (FAILED): ") + error.what();
    }
  });
  std::this_thread::sleep_for(1s);
  const std::string bob = bob_joins(target, run);
  attacker.join();
  return what + "; " + bob;
}

std::string unjoined_connections(const Target& target) {
  return during(target, "unjoined", [&](Clock::time_point until) {
    return fmt::format("{} connections from 8 addresses that never join, reopened as closed",
                       testing::hold_connections(target.control(), 8, 8, until));
  });
}

// The live view's port held by connections that send nothing, until the server runs out of
// descriptors; bob connects meanwhile and is let in once they are released.
std::string file_descriptors(const Target& target) {
  const tcp::endpoint view(asio::ip::make_address("127.0.0.1"), target.view_port);
  asio::io_context io;
  std::vector<tcp::socket> hogs;
  for (int k = 0; k < 300; ++k)
    hogs.push_back(testing::connect_from(io, testing::other_loopback(0), view));
  std::string bob;
  std::thread joining([&] { bob = bob_joins(target, "fds"); });
  std::this_thread::sleep_for(3s);
  hogs.clear();
  joining.join();
  return "300 idle connections to the live view's port (the server has 256 descriptors), released "
         "after 3 s; " +
         bob;
}

std::string view_bodies(const Target& target) {
  return during(target, "bodies", [&](Clock::time_point) {
    int refused = 0;
    for (int k = 0; k < 60; ++k) {
      const std::string answer =
          testing::http_exchange("127.0.0.1", target.view_port,
                                 "POST / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: "
                                 "33554432\r\nConnection: close\r\n\r\n" +
                                     std::string(4096, 'x'));
      refused += answer.rfind("HTTP/1.1 413", 0) == 0;
    }
    return fmt::format("60 POSTs declaring 32 MB bodies: {} refused with 413", refused);
  });
}

std::string view_browsers(const Target& target) {
  return during(target, "browsers", [&](Clock::time_point until) {
    std::vector<std::unique_ptr<testing::StalledWebSocket>> stalled;
    int upgraded = 0;
    for (int k = 0; k < 900; ++k) {
      stalled.push_back(std::make_unique<testing::StalledWebSocket>("127.0.0.1", target.view_port));
      upgraded += stalled.back()->upgraded();
    }
    std::this_thread::sleep_until(until);
    return fmt::format("900 WebSockets that never read: {} let in (the cap is 64)", upgraded);
  });
}

std::string dns_rebinding(const Target& target) {
  return during(target, "rebinding", [&](Clock::time_point) {
    const std::string answer =
        testing::http_exchange("127.0.0.1", target.view_port,
                               "GET /ws HTTP/1.1\r\nHost: evil.example\r\nOrigin: "
                               "http://evil.example\r\nUpgrade: websocket\r\n"
                               "Connection: Upgrade\r\nSec-WebSocket-Key: "
                               "dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n",
                               true);
    return "a handshake for Host and Origin evil.example: " + answer.substr(0, answer.find('\r'));
  });
}

std::string rotating_udp_sources(const Target& target) {
  return during(target, "udp", [&](Clock::time_point until) {
    asio::io_context io;
    std::vector<udp::socket> sources;
    for (std::uint32_t k = 0; k < 800; ++k) {
      udp::socket& socket = sources.emplace_back(io);
      socket.open(udp::v4());
      socket.bind({testing::other_loopback(k), 0});
    }
    std::mt19937 rng(3);
    testing::HostileDatagrams hostile(target.session, rng);
    std::uint64_t sent = 0;
    while (Clock::now() < until) {
      for (int k = 0; k < 100; ++k, ++sent) {
        std::error_code error;
        sources[sent % sources.size()].send_to(asio::buffer(hostile.next()), target.datagrams(), 0,
                                               error);
      }
      std::this_thread::sleep_for(1ms);
    }
    return fmt::format("{} hostile datagrams from 800 rotating addresses", sent);
  });
}

std::string big_join_frame(const Target& target) {
  return during(target, "frame", [&](Clock::time_point) {
    asio::io_context io;
    tcp::socket socket = testing::connect_from(io, testing::other_loopback(0), target.control());
    std::vector<std::uint8_t> start(wire::kFrameClearBytes, 0);
    wire::write_le(64u << 10, wire::kFrameLengthBytes, start.data());
    std::error_code error;
    asio::write(socket, asio::buffer(start), error);
    const auto deadline = Clock::now() + 5s;
    while (!testing::closed_by_peer(socket) && Clock::now() < deadline)
      std::this_thread::sleep_for(10ms);
    return std::string("an unjoined connection declaring a 64 KiB frame: ") +
           (testing::closed_by_peer(socket) ? "closed before its body" : "NOT closed");
  });
}

std::string sample_flood(const Target& target) {
  return during(target, "samples", [&](Clock::time_point until) {
    testing::RawParticipant flooder({.server_port = target.port, .slot = 2, .name = "flooder"},
                                    wire::ClientKeys(wire::development_key()));
    flooder.join();
    while (Clock::now() < until) {
      for (int k = 0; k < 20; ++k) flooder.send_sample({0.003, 0.002, 0.001});
      std::this_thread::sleep_for(1ms);
    }
    return fmt::format("a participant's {} valid samples at about 20,000 a second",
                       flooder.samples_sent());
  });
}

std::string log_forgery(const Target& target) {
  return during(target, "names", [&](Clock::time_point) {
    testing::RawParticipant forger(
        {.server_port = target.port, .slot = 2, .name = "eve\n[info] user 'admin' joined\x1b[2J"},
        wire::ClientKeys(wire::development_key()));
    try {
      forger.join();
      return std::string("a user name with a newline and an escape: JOINED");
    } catch (const Error& error) {
      return std::string("a user name with a newline and an escape: refused (") + error.what() +
             ")";
    }
  });
}

// A recording whose scene names a file beside its folder: verifying it must refuse the file
// by name, and say nothing of what is in it.
std::string crafted_recording(const Target& target, bool& read_outside) {
  const fs::path folder = target.dir / "received";
  fs::create_directories(folder);
  std::ofstream(target.dir / "secret.msh") << "root:SECRET-HASH:19000:0:99999:7:::\n";
  record::SessionConfig config;
  config.set_role("server");
  config.set_scene_yaml(std::regex_replace(testing::cube_scene_yaml(),
                                           std::regex(R"(mesh: \{box: .*\}\})"),
                                           "mesh: {file: ../secret.msh}"));
  config.set_scene_file((folder / "scene.yaml").string());
  {
    record::SessionRecorder recorder(folder / "crafted.mcap");
    recorder.config(config);
  }
  std::string why;
  try {
    verify_recording(folder / "crafted.mcap");
  } catch (const Error& error) {
    why = error.what();
  }
  read_outside =
      why.find("is outside") == std::string::npos || why.find("SECRET") != std::string::npos;
  return "replay --verify of a recording whose scene names ../secret.msh: " +
         (why.empty() ? "verified!" : why);
}

// A client's recording cut short inside its last chunk, with a byte changed in the chunk
// before (the last complete one): verifying it must fail on that chunk's CRC.
std::string altered_recording(const Target& target) {
  testing::Bytes bytes = testing::read_bytes(target.dir / "bob-unjoined.mcap");
  std::vector<testing::RawRecord> chunks;
  for (const testing::RawRecord& record : testing::walk(bytes))
    if (record.opcode == 0x06) chunks.push_back(record);
  if (chunks.size() < 3)
    return "bob's recording has fewer than 3 chunks: FAILED to make the attack";
  const testing::RawRecord& last = chunks.back();
  bytes.resize(last.offset + static_cast<std::size_t>(last.length) / 2);
  const testing::RawChunk altered = testing::read_chunk(bytes, chunks[chunks.size() - 2]);
  bytes[(altered.records_begin + altered.records_end) / 2] ^= 0x01;
  testing::write_bytes(target.dir / "received" / "altered.mcap", bytes);
  std::string why;
  try {
    verify_recording(target.dir / "received" / "altered.mcap");
  } catch (const Error& error) {
    why = error.what();
  }
  return "replay --verify of a recording cut short, a byte changed in its last complete chunk: " +
         (why.find("CRC") != std::string::npos ? "refused: " + why.substr(why.find("Chunk record"))
                                               : "NOT refused " + why);
}

// The server's resident set, sampled every 100 ms while it runs: its largest.
class RssWatch {
 public:
  explicit RssWatch(pid_t pid)
      : thread_([this, pid] {
          while (!stop_) {
            if (const auto usage = testing::usage_of(pid))
              peak_ = std::max<std::size_t>(peak_, usage->rss_bytes);
            std::this_thread::sleep_for(100ms);
          }
        }) {}
  ~RssWatch() {
    stop_ = true;
    thread_.join();
  }
  double peak_mb() const { return static_cast<double>(peak_.load()) / 1e6; }

 private:
  std::atomic<bool> stop_{false};
  std::atomic<std::size_t> peak_{0};
  std::thread thread_;
};

int run() {
  // Hundreds of sockets and connections from this process: its own descriptor limit up.
  rlimit limit{};
  getrlimit(RLIMIT_NOFILE, &limit);
  limit.rlim_cur = limit.rlim_max;
  setrlimit(RLIMIT_NOFILE, &limit);

  Target target;
  target.dir = testing::scratch_directory("attacks");
  testing::write_cube_scene(target.dir, "", 3);
  ChildProcess server(
      "/usr/bin/prlimit",
      {"--nofile=256", "--", testing::server_program(), "--scene",
       (target.dir / "cube.yaml").string(), "--listen", "127.0.0.1:0", "--view", "127.0.0.1:0",
       "--report", (target.dir / "server.json").string(), "--duration", "900", "--no-disk-cache"},
      target.dir / "server.log");
  if (!testing::wait_for_output(server, "live view at"))
    throw Error("the server did not start: " + server.log_text());
  const std::string started = server.log_text();
  std::smatch match;
  if (!std::regex_search(started, match, std::regex(R"(live view at http://127\.0\.0\.1:(\d+)/)")))
    throw Error("no live view address in the server's log");
  target.port = static_cast<std::uint16_t>(testing::listening_port(started));
  target.view_port = static_cast<std::uint16_t>(std::stoi(match[1]));
  target.session = testing::session_id(server);
  RssWatch rss(server.pid());
  fmt::print(stderr, "server on 127.0.0.1:{} (view {}), files in {}\n", target.port,
             target.view_port, target.dir.string());
  fmt::print(
      "# Attacks from the network, replayed\n\n"
      "`make attacks > docs/results/attacks.md` writes this page "
      "(`tests/attacks/cohaptic_attacks.cpp`). A "
      "cohaptic-server on loopback serves a three-tool cube with the live view, limited to 256 "
      "file descriptors. "
      "alice, a real client, presses and holds through every attack; during each, bob, another, "
      "joins, presses "
      "and leaves. The limits each attack meets are in [security](../security.md), \"Limits\".\n\n"
      "| | attack | what was sent, and what the server did | bob |\n|---|---|---|---|\n");

  auto alice = testing::scripted_client(target.dir, target.port, "alice", 0,
                                        testing::write_press(target.dir, "a", 3, 2, 2, 900));
  if (!testing::wait_for_output(*alice, "haptic loop at"))
    throw Error("alice did not join: " + alice->log_text());

  bool failed = false, read_outside = false;
  const auto report = [&](int number, const std::string& name, std::string outcome) {
    if (!server.running()) outcome += "; the server has ended (FAILED)";
    const bool bad = outcome.find("FAILED") != std::string::npos ||
                     outcome.find("bob did not join") != std::string::npos ||
                     outcome.find("bob's client failed") != std::string::npos ||
                     outcome.find("NOT") != std::string::npos ||
                     outcome.find("JOINED") != std::string::npos ||
                     outcome.find("verified!") != std::string::npos;
    failed = failed || bad;
    const std::size_t bob = outcome.rfind("; bob");
    const std::string what = outcome.substr(0, bob),
                      joined = bob == std::string::npos ? "" : outcome.substr(bob + 2);
    fmt::print("| {} | {} | {}{} | {} |\n", number, name, bad ? "**FAILED**: " : "", what, joined);
    std::fflush(stdout);
  };
  report(1, "connections never joining", unjoined_connections(target));
  report(2, "out of file descriptors", file_descriptors(target));
  report(3, "bodies to the live view", view_bodies(target));
  report(4, "browsers that never read", view_browsers(target));
  report(5, "DNS rebinding", dns_rebinding(target));
  report(6, "rotating UDP sources", rotating_udp_sources(target));
  report(7, "a large frame before joining", big_join_frame(target));
  report(8, "a participant's flood", sample_flood(target));
  report(9, "a crafted recording", crafted_recording(target, read_outside));
  report(10, "a forged log line", log_forgery(target));
  report(11, "an altered recording", altered_recording(target));

  // Alice ends her press (her report: her haptic rate through every attack). Then a user's
  // link drops (the process killed) and the user joins again at once, in the same slot.
  alice->signal(SIGINT);
  const bool alice_ended = alice->wait(testing::kPatience) == 0;
  const nlohmann::json throughout = nlohmann::json::parse(std::ifstream(target.dir / "alice.json"));
  auto dropping = testing::scripted_client(target.dir, target.port, "carol", 0,
                                           testing::write_press(target.dir, "c", 3, 2, 2, 60));
  bool rejoined = static_cast<bool>(testing::wait_for_output(*dropping, "haptic loop at"));
  dropping->signal(SIGKILL);
  dropping->wait(testing::kPatience);
  const auto again = testing::scripted_client(target.dir, target.port, "carol-again", 0,
                                              testing::write_press(target.dir, "c2", 3, 2, 2, 0.5));
  rejoined = rejoined && testing::wait_for_output(*again, "haptic loop at") &&
             again->wait(testing::kPatience) == 0;
  server.signal(SIGINT);
  server.wait(testing::kPatience);
  const nlohmann::json counted =
      nlohmann::json::parse(std::ifstream(target.dir / "server.json"))["server"];

  const double peak = rss.peak_mb();
  const double rate = throughout["haptic_rate_hz"].get<double>();
  const double faded_s = throughout["fades"]["total_s"].get<double>();
  // Judged as the session verdict judges it: against the bare timer that ran beside her loop.
  const bool rate_held = !misses_deadlines_of_its_own(throughout);
  const double missed = throughout["missed_deadlines"].get<double>();
  const double floor_missed = throughout["timer_floor"]["missed_deadlines"].get<double>();
  double host_steal_ms = 0;
  for (const nlohmann::json& cpu : throughout["timer_floor"]["cpus"])
    host_steal_ms = std::max(host_steal_ms, cpu["host_steal_ms"].get<double>());
  fmt::print(
      "\nalice, pressing through every attack: haptic rate {:.0f} Hz, period p99 {:.0f} us, {:.0f} "
      "missed deadlines "
      "(the bare timer beside her: {:.0f}; the host took {:.0f} ms of a CPU){}, IR age p99 {:.0f} "
      "ms, force faded "
      "for {:.2f} s in all; carol, her link dropped, joined again: {}\n",
      rate, throughout["period_us"]["p99"].get<double>(), missed, floor_missed, host_steal_ms,
      rate_held ? "" : " FAILED", throughout["ir_age_ms"]["p99"].get<double>(), faded_s,
      rejoined ? "yes" : "NO");
  fmt::print(
      "\nserver: {} unjoined connections evicted, {} accept errors, {} datagrams rate limited, {} "
      "over a user's "
      "budget, {} dropped by the kernel; steps failed {}\n",
      counted["connections"]["unjoined_evicted"].get<std::uint64_t>(),
      counted["connections"]["accept_errors"].get<std::uint64_t>(),
      counted["datagrams"]["rejected_by_reason"]["rate_limited"].get<std::uint64_t>(),
      counted["datagrams"]["over_budget"].get<std::uint64_t>(),
      counted["datagrams"]["dropped_by_kernel"].get<std::uint64_t>(),
      counted["failed_steps"]["count"].get<std::uint64_t>());
  fmt::print("\nserver's largest resident set: {:.1f} MB (at most {:.0f})\n", peak,
             kMaxServerRssMb);
  const std::uint64_t failed_steps = counted["failed_steps"]["count"].get<std::uint64_t>();
  failed = failed || failed_steps > 0 || !alice_ended || !rejoined || !rate_held || faded_s > 0 ||
           peak > kMaxServerRssMb || read_outside;
  fmt::print("\n**Verdict: {}**\n",
             failed ? "an attack got through (see FAILED above)" : "every attack held");
  return failed ? 1 : 0;
}

}  // namespace
}  // namespace cohaptic

int main() {
  try {
    return cohaptic::run();
  } catch (const std::exception& error) {
    std::fprintf(stderr, "cohaptic_attacks: %s\n", error.what());
    return 2;
  }
}
