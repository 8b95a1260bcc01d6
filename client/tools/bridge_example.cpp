// cohaptic-bridge-example: plays the vendor-SDK side of the external-device bridge
// (client/device/BRIDGE.md), for testing a client without hardware and as a worked example.
//
// Sends pose packets at --rate Hz (default 1000) to the client at --client HOST:PORT,
// following a sine along one axis or a circle in the xy plane around --center, prints the
// forces it receives once a second, and stops after --duration seconds (or on Ctrl-C).
// Units on the command line: mm, Hz, s; on the wire: m, N, s.
//
//   cohaptic-client ... --device bridge:7700 &
//   cohaptic-bridge-example --client 127.0.0.1:7700 --motion circle --amplitude 10 --frequency 0.5
#include <CLI/CLI.hpp>

#include <Eigen/Core>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <fmt/format.h>
#include <numbers>
#include <string>
#include <thread>

#include "client/device/bridge_peer.h"
#include "common/util/error.h"
#include "common/util/log_to_stderr.h"

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop.store(true); }

struct Motion {
  std::string kind = "sine";                         // sine | circle
  char axis = 'z';                                   // sine only
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // [m]
  double amplitude = 0.01;                           // [m]
  double frequency = 0.5;                            // [Hz]

  Eigen::Vector3d at(double t) const {
    const double phase = 2.0 * std::numbers::pi * frequency * t;
    Eigen::Vector3d p = center;
    if (kind == "circle") {
      p.x() += amplitude * std::cos(phase);
      p.y() += amplitude * std::sin(phase);
    } else {
      p[axis - 'x'] += amplitude * std::sin(phase);
    }
    return p;
  }
};

}  // namespace

int main(int argc, char** argv) {
  cohaptic::log_to_stderr();  // anything the client library logs; stdout carries the forces
  CLI::App app{
      "Plays the vendor-SDK side of the cohaptic external-device bridge: sends poses, prints "
      "forces."};
  std::string client;
  std::string axis = "z";
  std::vector<double> center_mm{0, 0, 0};
  Motion motion;
  double amplitude_mm = 10.0;
  double rate_hz = 1000.0;
  double duration_s = 10.0;
  app.add_option("--client", client,
                 "the client's bridge address, HOST:PORT (its device spec bridge:[HOST:]PORT)")
      ->required();
  app.add_option("--motion", motion.kind, "sine (along --axis) or circle (in the xy plane)")
      ->check(CLI::IsMember({"sine", "circle"}))
      ->capture_default_str();
  app.add_option("--axis", axis, "axis of the sine")
      ->check(CLI::IsMember({"x", "y", "z"}))
      ->capture_default_str();
  app.add_option("--amplitude", amplitude_mm, "amplitude (sine) or radius (circle) [mm]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--frequency", motion.frequency, "[Hz]")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--center", center_mm, "centre of the motion, x y z [mm]")
      ->expected(3)
      ->capture_default_str();
  app.add_option("--rate", rate_hz, "pose packets per second")
      ->check(CLI::Range(1.0, 100000.0))
      ->capture_default_str();
  app.add_option("--duration", duration_s, "stop after this many seconds")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  motion.axis = axis[0];
  motion.amplitude = amplitude_mm * 1e-3;
  motion.center = Eigen::Vector3d(center_mm[0], center_mm[1], center_mm[2]) * 1e-3;

  const auto colon = client.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    fmt::print(stderr, "--client: expected HOST:PORT, found '{}'\n", client);
    return 2;
  }
  std::string host = client.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']')
    host = host.substr(1, host.size() - 2);
  int port = 0;
  try {
    port = std::stoi(client.substr(colon + 1));
  } catch (const std::exception&) {
    port = 0;
  }
  if (port < 1 || port > 65535) {
    fmt::print(stderr, "--client: expected a port from 1 to 65535 in '{}'\n", client);
    return 2;
  }

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    cohaptic::BridgePeer peer(host, static_cast<std::uint16_t>(port));
    fmt::print("sending {} poses at {} Hz from udp port {} to {} for {} s\n", motion.kind, rate_hz,
               peer.local_port(), peer.client(), duration_s);

    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    const auto period =
        std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(1.0 / rate_hz));
    auto deadline = start;
    double next_report = 1.0;
    std::uint64_t sent_at_report = 0;
    std::uint64_t forces_at_report = 0;
    std::uint64_t late_ticks = 0;
    for (std::uint64_t tick = 0; !g_stop.load(); ++tick) {
      const double t = std::chrono::duration<double>(clock::now() - start).count();
      if (t >= duration_s) break;
      peer.send_pose(motion.at(t), t);
      peer.poll_forces();
      if (t >= next_report) {
        const auto& force = peer.newest_force();
        if (force) {
          fmt::print(
              "t {:6.2f} s  sent {:5}  forces {:5}  f [{:+.3f} {:+.3f} {:+.3f}] N (limit {} N, {}) "
              " round trip {:.2f} ms\n",
              t, peer.next_sequence() - sent_at_report, peer.forces_received() - forces_at_report,
              force->force.x(), force->force.y(), force->force.z(), force->force_limit,
              (force->flags & cohaptic::bridge::kClientValid) ? "client valid" : "client invalid",
              (t - force->device_time_s) * 1e3);
        } else {
          fmt::print(
              "t {:6.2f} s  sent {:5}  no force packet yet (is the client listening on {}?)\n", t,
              peer.next_sequence() - sent_at_report, peer.client());
        }
        std::fflush(stdout);
        sent_at_report = peer.next_sequence();
        forces_at_report = peer.forces_received();
        next_report += 1.0;
      }
      // Absolute deadlines: a late tick is counted and the schedule kept (no drift, no burst).
      deadline += period;
      const auto now = clock::now();
      if (now > deadline) {
        ++late_ticks;
        deadline = now;
      }
      std::this_thread::sleep_until(deadline);
    }
    fmt::print(
        "done: {} poses sent ({} refused by the socket), {} forces received, {} dropped, {} late "
        "ticks\n",
        peer.next_sequence(), peer.send_failed(), peer.forces_received(), peer.forces_dropped(),
        late_ticks);
  } catch (const cohaptic::Error& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 1;
  }
  return 0;
}
