// End-to-end tests with the real programs on loopback: a cohaptic-server process and
// cohaptic-client processes with scripted devices, on a soft two-tool cube.
//   - the forces each client output equal an offline evaluation of the IRs it received
//     for the tool positions it used, and the full FEM solve for those positions;
//   - P0 is stepwise and P1 smooth when the simulation rate is capped;
//   - an injected shift delay is measured back within 1 ms;
//   - hostile datagrams are rejected and counted by reason, and a flood of them does not
//     move the haptic period beyond the machine's timer floor;
//   - killing the server fades the clients' force to zero; a restarted server takes them back.
#include <gtest/gtest.h>
#include <signal.h>

#include <asio.hpp>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "common/model/static_contact.h"
#include "common/model/model.h"
#include "common/scene/load_scene.h"
#include "common/util/error.h"
#include "common/ir/client_condensation.h"
#include "common/ir/evaluate_force.h"
#include "proto/record/recording.h"
#include "proto/wire/datagram_codec.h"
#include "proto/wire/ir_convert.h"
#include "proto/wire/session_key.h"
#include "proto/wire/traffic_keys.h"
#include "support/cube_session.h"
#include "support/process.h"
#include "support/evaluate_static.h"

namespace cohaptic {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::ChildProcess;
using testing::write_press;
using Session = testing::CubeSession;

struct Tick {
  double time = 0;
  Eigen::Vector3d own, remote, force, evaluated;
  std::uint64_t epoch = 0;
  int flags = 0;
  double fade = 1;
};

// The haptic ticks of a client's recording.
std::vector<Tick> read_ticks(const fs::path& file) {
  const record::Recording recording = record::read_recording(file);
  std::vector<Tick> ticks;
  for (const record::HapticTick& t : recording.ticks) {
    Tick tick;
    tick.time = static_cast<double>(t.time_ns()) * 1e-9;
    tick.own = wire::from_wire(t.own());
    tick.remote =
        t.remotes_size() > 0 ? wire::from_wire(t.remotes(0)) : Eigen::Vector3d::Constant(NAN);
    tick.force = wire::from_wire(t.force());
    tick.evaluated = wire::from_wire(t.evaluated());
    tick.epoch = t.ir_epoch();
    tick.flags = static_cast<int>(t.flags());
    tick.fade = t.fade();
    ticks.push_back(tick);
  }
  return ticks;
}

// The IRs of a client's recording, by epoch; those sent as compliance rows completed in
// arrival order, as the client did.
std::map<std::uint64_t, std::unique_ptr<PreparedIR>> read_irs(const fs::path& file) {
  std::map<std::uint64_t, std::unique_ptr<PreparedIR>> irs;
  ClientCondensation condensation;
  for (const record::RecordedIr& recorded : record::read_recording(file).irs) {
    IntermediateRepresentation ir = wire::from_wire(recorded.ir());
    condensation.complete(condensed_fem(ir));
    irs[recorded.ir().epoch()] = std::make_unique<PreparedIR>(prepare_ir(std::move(ir)));
  }
  return irs;
}

TEST(EndToEnd, ClientForcesEqualOfflineEvaluationAndTheFullSolve) {
  Session session("e2e-forces",
                  {"--duration", "30", "--display", "display", "--display-rate-hz", "20"});
  const auto a = session.client("alice", 0, write_press(session.dir, "a", -20, 2, 4, 0.6));
  const auto b = session.client("bob", 1, write_press(session.dir, "b", 20, -2, 4, 0.6));
  ASSERT_EQ(a->wait(testing::kPatience), 0) << a->log_text();
  ASSERT_EQ(b->wait(testing::kPatience), 0) << b->log_text();
  session.stop_server();

  // The deformation for display: under node translation the contact nodes follow the
  // tool, so the largest surface displacement is the depth reached: 4 mm pressed from
  // 0.5 mm above the surface.
  const nlohmann::json server_report = session.report("server")["server"];
  EXPECT_NEAR(server_report["max_surface_displacement_mm"].get<double>(), 3.5, 0.05);
  std::ifstream index(session.dir / "display" / "surface.pvd");
  const std::string pvd((std::istreambuf_iterator<char>(index)), std::istreambuf_iterator<char>());
  EXPECT_GT(std::count(pvd.begin(), pvd.end(), '\n'), 20) << "display frames listed in surface.pvd";
  EXPECT_TRUE(fs::exists(session.dir / "display" / "surface-000010.vtu"));

  const Model model = build_model(load_scene(session.dir / "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  for (const std::string user : {"alice", "bob"}) {
    const std::vector<Tick> ticks = read_ticks(session.dir / (user + ".mcap"));
    ASSERT_GT(ticks.size(), 1500u) << user;
    const std::map<std::uint64_t, std::unique_ptr<PreparedIR>> irs =
        read_irs(session.dir / (user + ".mcap"));
    int contact_ticks = 0, offline_checked = 0, reference_checked = 0;
    for (std::size_t i = 0; i < ticks.size(); ++i) {
      const Tick& t = ticks[i];
      if (!(t.flags & kInContact) || t.epoch == 0) continue;
      ++contact_ticks;
      ASSERT_TRUE(irs.count(t.epoch)) << "IR " << t.epoch << " not recorded";
      const auto& ir = irs.at(t.epoch);
      // The same IR and positions give the same force, bit for bit.
      const Eigen::Vector3d remote = t.remote;
      const ForceSample offline = testing::evaluate_static(
          *ir, t.own, std::span(&remote, condensed_fem(ir->ir).remotes.empty() ? 0 : 1));
      ASSERT_EQ(offline.force, t.evaluated) << user << " tick " << i;
      ++offline_checked;
      // And the full FEM solve with both tools at those positions, where both sit on the
      // IR's triangles (every 50th contact tick; a full solve takes a while).
      if (contact_ticks % 50 != 0 || !remote.allFinite()) continue;
      std::vector<PressedTool> pressed = {{t.own, 0}, {remote, 0}};
      const std::vector<ContactQuery> contacts = find_tool_contacts(body, pressed);
      bool covered = contacts[0].contact.has_value();
      if (covered) {
        bool in_patch = false;
        for (const IrTriangle& tri : condensed_fem(ir->ir).patch)
          in_patch |= tri.surface_index == contacts[0].contact->triangle;
        covered =
            in_patch && (!contacts[1].contact || [&] {
              const Triangle& tri = body.surface.triangles[contacts[1].contact->triangle];
              for (int k = 0; k < 3; ++k)
                if (condensed_fem(ir->ir).remotes.empty() ||
                    body.mesh.node_tags[tri[k]] !=
                        condensed_fem(ir->ir).node_ids[condensed_fem(ir->ir).remotes[0].nodes[k]])
                  return false;
              return true;
            }());
      }
      if (!covered) continue;
      const Eigen::Vector3d expected =
          contact_reactions_reference(body, contacts, {}, ContactModel::node_translation)[0]
              .reaction;
      EXPECT_LE((t.evaluated - expected).norm(), 1e-9 * expected.norm()) << user << " tick " << i;
      ++reference_checked;
    }
    std::printf(
        "  %s: %zu ticks, %d in contact, %d re-evaluated offline, %d checked against the full "
        "solve\n",
        user.c_str(), ticks.size(), contact_ticks, offline_checked, reference_checked);
    EXPECT_GT(contact_ticks, 300);
    EXPECT_GE(reference_checked, 5);
    const nlohmann::json report = session.report(user);
    EXPECT_GT(report["coupling_n"]["peak"].get<double>(),
              0.1 * report["force_n"]["peak"].get<double>());
  }
}

// Distinct force values per second while pressing.
double force_updates_per_second(const std::vector<Tick>& ticks) {
  std::set<std::tuple<double, double, double>> distinct;
  double first = -1, last = 0;
  for (const Tick& t : ticks) {
    if (t.force.norm() < 1e-6) continue;
    distinct.emplace(t.force.x(), t.force.y(), t.force.z());
    if (first < 0) first = t.time;
    last = t.time;
  }
  return last > first ? static_cast<double>(distinct.size()) / (last - first) : 0;
}

TEST(EndToEnd, P0IsStepwiseAndP1SmoothAtACappedSimulationRate) {
  std::map<std::string, double> rate;
  for (const std::string protocol : {"P0", "P1"}) {
    Session session("e2e-" + protocol,
                    {"--protocol", protocol, "--sim-rate-hz", "40", "--duration", "30"});
    const auto a = session.client("alice", 0, write_press(session.dir, "a", 3, 2, 5, 0.2));
    ASSERT_EQ(a->wait(testing::kPatience), 0) << a->log_text();
    session.stop_server();
    rate[protocol] = force_updates_per_second(read_ticks(session.dir / "alice.mcap"));
    std::printf("  %s at a 40 Hz simulation: %.0f distinct forces per second\n", protocol.c_str(),
                rate[protocol]);
  }
  EXPECT_LE(rate["P0"], 45);   // one force per simulation step, held in between
  EXPECT_GE(rate["P1"], 500);  // a new force every haptic tick
}

TEST(EndToEnd, AnInjectedShiftDelayIsMeasuredBack) {
  Session session("e2e-delay", {"--shift-delay-ms", "20", "--duration", "30"});
  const auto a = session.client("alice", 0, write_press(session.dir, "a", 3, 2, 3, 0.2));
  ASSERT_EQ(a->wait(testing::kPatience), 0) << a->log_text();
  session.stop_server();
  const nlohmann::json client = session.report("alice");
  const double one_way = client["one_way_delay_ms"]["p50"].get<double>();
  const double round_trip = client["clock"]["round_trip_ms"].get<double>();
  std::printf(
      "  injected 20 ms each way: measured one-way %.2f ms (p50), clock round trip %.2f ms\n",
      one_way, round_trip);
  EXPECT_NEAR(one_way, 20.0, 1.0);
  EXPECT_NEAR(round_trip, 40.0, 2.0);
  EXPECT_EQ(session.report("server")["server"]["injected"]["shift_delay_ms"], 20.0);
}

TEST(EndToEnd, HostileDatagramsAreRejectedByReasonAndDoNotMoveTheHapticPeriod) {
  Session session("e2e-hostile", {"--duration", "30"});
  const auto a = session.client("alice", 0, write_press(session.dir, "a", 3, 2, 3, 2.0));
  // The flood is aimed at a running haptic loop (whose period it must not move).
  ASSERT_TRUE(testing::wait_for_output(*a, "haptic loop at"));
  std::smatch match;
  const std::string log = a->log_text();
  ASSERT_TRUE(std::regex_search(log, match, std::regex(R"(UDP port (\d+))")));
  const auto client_port = static_cast<std::uint16_t>(std::stoi(match[1]));

  asio::io_context io;
  asio::ip::udp::socket socket(io, asio::ip::udp::endpoint(asio::ip::udp::v4(), 0));
  const asio::ip::udp::endpoint server(asio::ip::make_address("127.0.0.1"),
                                       static_cast<std::uint16_t>(session.port));
  const asio::ip::udp::endpoint client(asio::ip::make_address("127.0.0.1"), client_port);
  // The flood may know the public development key: it derives slot 0's key, and still has
  // neither the session id nor the sealer's salt.
  const wire::TrafficKey key = wire::participant_key(wire::development_key(), 0);
  const auto send = [&](const std::vector<std::uint8_t>& bytes, const asio::ip::udp::endpoint& to) {
    socket.send_to(asio::buffer(bytes), to);
  };
  const auto datagram = [&](std::uint32_t version, std::uint64_t sequence, double x) {
    wire::Datagram d;
    d.mutable_header()->set_protocol_version(version);
    d.mutable_header()->set_sender(1);
    d.mutable_header()->set_sequence(sequence);
    d.mutable_tool()->set_user(0);
    d.mutable_tool()->mutable_position()->set_x(x);
    return wire::encode_datagram(d, {key, 77});
  };
  // One of each kind to the server (its session id is unknown to us: wrong_session, except
  // where an earlier check fires first).
  send({1, 2, 3}, server);                           // truncated
  send(std::vector<std::uint8_t>(2000, 7), server);  // oversized
  std::vector<std::uint8_t> forged = datagram(wire::kProtocolVersion, 5, 0.0);
  forged.back() ^= 0x40;
  send(forged, server);                                        // bad_tag
  send(datagram(wire::kProtocolVersion - 1, 5, 0.0), server);  // bad_version: an older peer
  send(datagram(wire::kProtocolVersion, 5, 0.0), server);      // wrong_session
  // A flood at the client while its haptic loop runs: random bytes and forged datagrams.
  std::mt19937 rng(3);
  for (int i = 0; i < 20000; ++i) {
    std::vector<std::uint8_t> junk(16 + rng() % 200);
    for (auto& byte : junk) byte = static_cast<std::uint8_t>(rng());
    send(i % 2
             ? junk
             : datagram(wire::kProtocolVersion, 1000 + static_cast<std::uint64_t>(i), std::nan("")),
         client);
    if (i % 1000 == 999)
      std::this_thread::sleep_for(5ms);  // stimulus: a flood in bursts the kernel can take
  }
  ASSERT_EQ(a->wait(testing::kPatience), 0) << a->log_text();
  session.stop_server();

  const nlohmann::json server_reasons =
      session.report("server")["server"]["datagrams"]["rejected_by_reason"];
  for (const char* reason : {"truncated", "oversized", "bad_tag", "bad_version", "wrong_session"})
    EXPECT_GE(server_reasons[reason].get<int>(), 1) << reason << ": " << server_reasons.dump();
  const nlohmann::json report = session.report("alice");
  const nlohmann::json& reasons = report["datagrams"]["rejected_by_reason"];
  // 20,000 were sent; the kernel may drop some of a flood before the client reads them, but
  // most must be seen and every one seen must be rejected: inspected until the source had
  // failed 64 times, then dropped unread (rate_limited) but for 16 a second.
  EXPECT_GE(report["datagrams"]["rejected"].get<int>(), 15000) << reasons.dump();
  EXPECT_GE(reasons["rate_limited"].get<int>(), 14000) << reasons.dump();
  EXPECT_LE(reasons["accepted"].get<int>(), report["datagrams"]["received"].get<int>() - 15000);
  const double p99 = report["period_us"]["p99"].get<double>();
  const double floor_p99 = report["timer_floor"]["period_us"]["p99"].get<double>();
  std::printf(
      "  under a flood of 20,000 hostile datagrams: haptic period p99 %.0f us, timer floor p99 "
      "%.0f us\n",
      p99, floor_p99);
  // The floor is measured before the session, the flood's period during it: on an idle
  // machine they agree within ~50 us; on a loaded one (a 2 ms floor) both swing by a
  // tenth or more between the two measurements, so the margin grows with the floor. A flood
  // handled on the haptic thread would cost milliseconds per burst, far beyond either.
  EXPECT_LE(p99, std::max(1100.0, floor_p99 * 1.25 + 150));
  EXPECT_EQ(report["non_finite_ticks"], 0);
}

// Why IRs travel over TCP: on a lossy link every IR still arrives, whereas an IR sent as
// UDP fragments would be lost whenever any one of its fragments is, and an IR sent as
// compliance rows (the default) is of no use without every one before it.
TEST(EndToEnd, OnALossyLinkEveryIrArrivesOverTcp) {
  Session session("e2e-loss", {"--loss", "0.2", "--seed", "7", "--duration", "30"});
  // Press, then slide across the face: every triangle change is a new IR.
  const fs::path slide = session.dir / "slide.yaml";
  std::ofstream(slide) << R"(
units: mm
start: [-40, 2, 6]
segments:
  - {move_to: [-40, 2, -2], speed: 20}
  - {move_by: [80, 0, 0], speed: 40}
  - {move_to: [40, 2, 6], speed: 20}
)";
  const auto a = session.client("alice", 0, slide);
  ASSERT_EQ(a->wait(testing::kPatience), 0) << a->log_text();
  session.stop_server();
  const nlohmann::json server = session.report("server")["server"];
  const nlohmann::json client = session.report("alice");
  const auto sent = server["irs_sent"].get<std::uint64_t>();
  const auto received = client["ir"]["received"].get<std::uint64_t>();
  const double mean_bytes = static_cast<double>(client["ir"]["bytes"].get<std::uint64_t>()) /
                            static_cast<double>(received);
  const double fragments =
      std::ceil(mean_bytes / static_cast<double>(wire::kMaxDatagramBytes - 100));
  const double udp_survival = std::pow(0.8, fragments);
  const double udp_chain = std::pow(udp_survival, static_cast<double>(received));
  std::printf(
      "  20 %% datagram loss: %lu of %lu IRs arrived over TCP; as UDP, an IR of %.0f bytes (%.0f "
      "fragments) "
      "would arrive with probability %.2g, all %lu of them (each needs the ones before) %.2g\n",
      static_cast<unsigned long>(received), static_cast<unsigned long>(sent), mean_bytes, fragments,
      udp_survival, static_cast<unsigned long>(received), udp_chain);
  EXPECT_EQ(received, sent);
  EXPECT_GE(received, 5u);
  EXPECT_GT(
      client["remote_samples_received"].get<int>() + client["datagrams"]["received"].get<int>(), 0);
  EXPECT_EQ(client["ir"]["condensed"].get<std::uint64_t>(), received)
      << "every IR came as compliance rows";
  EXPECT_LT(udp_chain, 0.1);
  // The datagrams did suffer: about 20 % lost each way.
  const double to_lost = server["injected"]["datagrams_dropped_to_clients"].get<double>();
  const double from_lost = server["injected"]["datagrams_dropped_from_clients"].get<double>();
  EXPECT_NEAR(to_lost / (to_lost + server["datagrams"]["sent"].get<double>()), 0.2, 0.05);
  EXPECT_NEAR(from_lost / server["datagrams"]["accepted"].get<double>(), 0.2, 0.05);
}

// When a client's force faded out and came back, from its recording: the first tick at
// which an evaluated force is faded, the first tick after it at zero, and the first tick
// after that with a full force again (seconds from the first tick; -1: not (yet) seen).
struct FadeTimeline {
  double started = -1, zero_at = -1, back_at = -1;
};

FadeTimeline fade_timeline(const std::vector<Tick>& ticks) {
  FadeTimeline timeline;
  if (ticks.empty()) return timeline;
  for (const Tick& t : ticks) {
    const double s = t.time - ticks.front().time;
    if (timeline.started < 0 && t.fade < 1 && t.evaluated.norm() > 0) timeline.started = s;
    if (timeline.started >= 0 && timeline.zero_at < 0 && t.fade == 0) timeline.zero_at = s;
    if (timeline.zero_at >= 0 && timeline.back_at < 0 && t.fade == 1 && t.force.norm() > 0)
      timeline.back_at = s;
  }
  return timeline;
}

// The ticks of a recording a running client is writing: what it has flushed so far (none
// before its first flush).
std::vector<Tick> ticks_so_far(const fs::path& file) {
  try {
    return read_ticks(file);
  } catch (const Error&) {
    return {};
  }
}

TEST(EndToEnd, AServerRestartFadesTheForceOutAndTheClientReconnects) {
  auto session =
      std::make_unique<Session>("e2e-restart", std::vector<std::string>{"--duration", "120"});
  const int port = session->port;
  // Press 3 mm from 0.5 mm above the face and hold far longer than any restart takes: the
  // test ends the client once its force is back.
  const auto a = session->client("alice", 0, write_press(session->dir, "a", 3, 2, 3, 100.0));
  const fs::path recording = session->dir / "alice.mcap";
  ASSERT_TRUE(testing::wait_until(
      [&] {
        const std::vector<Tick> ticks = ticks_so_far(recording);
        return std::any_of(ticks.begin(), ticks.end(),
                           [](const Tick& t) { return t.own.z() < -2.4e-3 && t.force.norm() > 0; });
      },
      "alice's recording to show her holding the press (2.5 mm deep, with a force)"))
      << a->log_text();
  session->server->signal(SIGKILL);
  ASSERT_TRUE(session->server->wait(testing::kPatience).has_value());
  ASSERT_TRUE(
      testing::wait_until([&] { return fade_timeline(ticks_so_far(recording)).zero_at >= 0; },
                          "alice's force to fade out to zero after the server was killed"))
      << a->log_text();
  ChildProcess restarted(
      testing::server_program(),
      {"--scene", (session->dir / "cube.yaml").string(), "--listen",
       fmt::format("127.0.0.1:{}", port), "--duration", "120", "--no-disk-cache"},
      session->dir / "server2.log");
  ASSERT_TRUE(testing::wait_for_output(restarted, "listening on"));
  ASSERT_TRUE(
      testing::wait_until([&] { return fade_timeline(ticks_so_far(recording)).back_at >= 0; },
                          "alice's force to come back after the server's restart"))
      << a->log_text() << restarted.log_text();
  a->signal(SIGINT);
  ASSERT_EQ(a->wait(testing::kPatience), 0) << a->log_text();
  restarted.signal(SIGINT);
  restarted.wait(testing::kPatience);

  // The shape, from the whole recording: force before, zero within the fade time of the
  // fade's start (which comes max age, 0.5 s, after the last confirmation), force again
  // after the reconnect.
  const std::vector<Tick> ticks = read_ticks(recording);
  ASSERT_FALSE(ticks.empty());
  const FadeTimeline timeline = fade_timeline(ticks);
  std::printf("  force fading from %.3f s, zero at %.3f s, back at %.3f s\n", timeline.started,
              timeline.zero_at, timeline.back_at);
  ASSERT_GT(timeline.started, 0) << "the force never faded";
  ASSERT_GT(timeline.zero_at, 0) << "the force never reached zero";
  EXPECT_LE(timeline.zero_at - timeline.started, 0.1 + 0.02);  // the fade time, plus a tick or two
  EXPECT_GT(timeline.back_at, timeline.zero_at) << "the force did not come back after the restart";
  EXPECT_GE(session->report("alice")["reconnects"].get<int>(), 1);
  for (const Tick& t : ticks) EXPECT_TRUE(t.force.allFinite());
}

}  // namespace
}  // namespace cohaptic
