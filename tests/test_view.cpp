// The live view's parts without a browser (view/): the web server against real sockets
// (what it serves, in what order, who it refuses, what a bad message closes, how a stalled
// browser is kept from growing its queue), the recording's player against a recording made
// up here, and a frame against the simulation it is built from. The page in a real
// browser is tests/test_view_browser.cpp's.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "common/model/shown_surface.h"
#include "common/sim/elastic_states.h"
#include "common/sim/ir_build_options.h"
#include "common/sim/loaded_columns.h"
#include "common/sim/scene_simulation.h"
#include "common/sim/simulation.h"
#include "common/util/error.h"
#include "common/util/monotonic_clock.h"
#include "proto/record/recording.h"
#include "proto/wire/header.h"
#include "server/simulation_loop.h"
#include "support/cube_scene.h"
#include "support/process.h"
#include "support/process_usage.h"
#include "support/sanitizer_owns_malloc.h"
#include "support/wait.h"
#include "support/websocket_client.h"
#include "view/live_view.h"
#include "view/browser_input.h"
#include "view/replay_player.h"
#include "view/view_server.h"
#include "view/view_token.h"

namespace cohaptic {
namespace {

using namespace std::chrono_literals;
using testing::WebSocketClient;

view::ViewServerOptions local_options(const std::string& token = "") {
  view::ViewServerOptions options;
  options.token = token;
  options.assets = COHAPTIC_VIEW_WEB_DIR;
  options.proto = COHAPTIC_PROTO_DIR;
  return options;
}

std::string data_url(const view::ViewServer& server, const std::string& query = "") {
  return "ws://127.0.0.1:" + std::to_string(server.port()) + "/ws" + query;
}

TEST(ViewServer, ServesThePageItsLibrariesAndItsSchemaAndNothingElse) {
  view::ViewServer server(local_options());
  server.start();
  const auto get = [&](const std::string& path) {
    return testing::http_get("127.0.0.1", server.port(), path);
  };
  const std::string page = get("/");
  EXPECT_EQ(page.rfind("HTTP/1.1 200", 0), 0u) << page.substr(0, 200);
  EXPECT_NE(page.find("<!DOCTYPE html>"), std::string::npos);
  EXPECT_NE(page.find("text/html"), std::string::npos);
  EXPECT_NE(get("/view.js?cache=1").find("cohapticView"), std::string::npos);
  EXPECT_NE(get("/lib/three.module.min.js").find("REVISION"), std::string::npos);
  EXPECT_NE(get("/lib/protobuf.min.js").find("protobuf"), std::string::npos);
  EXPECT_NE(get("/proto/cohaptic/view.proto").find("package cohaptic.view;"), std::string::npos);
  for (const char* path :
       {"/../CMakeLists.txt", "/lib/../../CMakeLists.txt", "/lib/SHA256SUMS", "/missing"})
    EXPECT_EQ(get(path).rfind("HTTP/1.1 404", 0), 0u) << path;
  EXPECT_EQ(server.counters().http_requests, 9u);
}

TEST(ViewServer, AMissingLibraryIsAnErrorNamingItAndHowToRestoreIt) {
  view::ViewServerOptions options = local_options();
  options.assets = ::testing::TempDir() + "/no-such-web-dir";
  try {
    view::ViewServer server(options);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("index.html"), std::string::npos) << e.what();
  }
  // The page present, its libraries not: the message says how to restore them.
  const std::filesystem::path web =
      std::filesystem::path(::testing::TempDir()) / "web-without-libraries";
  std::filesystem::create_directories(web);
  for (const char* file : {"index.html", "view.js", "style.css"})
    std::filesystem::copy_file(std::filesystem::path(COHAPTIC_VIEW_WEB_DIR) / file, web / file,
                               std::filesystem::copy_options::overwrite_existing);
  options.assets = web;
  try {
    view::ViewServer server(options);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("three.module.min.js"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("refresh-view-libs.sh"), std::string::npos) << e.what();
  }
}

TEST(ViewServer, ABrowserGetsTheSceneFirstThenTheNewestOfEachChannel) {
  view::ViewServer server(local_options());
  server.start();
  // Before anyone watches: the scene, three frames and a status. Only the newest of each counts.
  server.publish(view::Channel::frame, "frame 1");
  server.publish(view::Channel::scene, "scene");
  server.publish(view::Channel::frame, "frame 2");
  server.publish(view::Channel::status, "status 1");
  server.publish(view::Channel::frame, "frame 3");
  WebSocketClient browser(data_url(server));
  ASSERT_TRUE(browser.wait_open(10s));
  ASSERT_TRUE(browser.wait_messages(3, 10s));
  EXPECT_EQ(browser.messages(), (std::vector<std::string>{"scene", "frame 3", "status 1"}));
  server.publish(view::Channel::frame, "frame 4");
  ASSERT_TRUE(browser.wait_messages(4, 10s));
  EXPECT_EQ(browser.messages().back(), "frame 4");
  // A second browser gets the same start, never the frames it missed.
  WebSocketClient late(data_url(server));
  ASSERT_TRUE(late.wait_messages(3, 10s));
  EXPECT_EQ(late.messages(), (std::vector<std::string>{"scene", "frame 4", "status 1"}));
  EXPECT_EQ(server.counters().browsers, 2);
  EXPECT_EQ(server.counters().connections, 2u);
}

TEST(ViewServer, OffLoopbackATokenIsRequiredAndAForeignPageIsRefused) {
  EXPECT_TRUE(view::is_loopback("127.0.0.1"));
  EXPECT_TRUE(view::is_loopback("127.1.2.3"));
  EXPECT_TRUE(view::is_loopback("::1"));
  EXPECT_FALSE(view::is_loopback("0.0.0.0"));
  EXPECT_FALSE(view::is_loopback("10.77.0.1"));
  EXPECT_EQ(view::access_token("127.0.0.1", std::nullopt), "");
  const std::string drawn = view::access_token("0.0.0.0", std::nullopt);
  EXPECT_EQ(drawn.size(), 32u);
  EXPECT_NE(drawn, view::access_token("0.0.0.0", std::nullopt));

  const std::string token = "abcdef0123456789abcd";
  view::ViewServer server(local_options(token));
  server.publish(view::Channel::scene, "scene");
  server.start();
  EXPECT_NE(server.url().find("?token=" + token), std::string::npos);
  WebSocketClient without(data_url(server));
  WebSocketClient wrong(data_url(server, "?token=abcdef0123456789abce"));
  WebSocketClient foreign(data_url(server, "?token=" + token), "http://elsewhere.example");
  WebSocketClient right(data_url(server, "?token=" + token),
                        "http://127.0.0.1:" + std::to_string(server.port()));
  EXPECT_FALSE(without.wait_open(10s));
  EXPECT_FALSE(wrong.wait_open(10s));
  EXPECT_FALSE(foreign.wait_open(10s));
  EXPECT_EQ(without.refused_status(), 403);
  EXPECT_EQ(wrong.refused_status(), 403);
  EXPECT_EQ(foreign.refused_status(), 403);
  ASSERT_TRUE(right.wait_open(10s));
  ASSERT_TRUE(right.wait_messages(1, 10s));
  EXPECT_EQ(right.messages().front(), "scene");
  EXPECT_EQ(server.counters().refused, 3u);
}

// DNS rebinding: a web page on a name made to resolve to 127.0.0.1 sends that name as Host
// (and as Origin). Without a token only this machine's names are served the data.
TEST(ViewServer, WithoutATokenOnlyThisMachinesNamesGetTheData) {
  for (const char* host : {"127.0.0.1", "127.0.0.1:7480", "localhost:7480", "LOCALHOST",
                           "[::1]:7480", "::1", "127.9.9.9"})
    EXPECT_TRUE(view::names_this_machine(host)) << host;
  for (const char* host : {"evil.example", "evil.example:7480", "localhost.evil.example",
                           "10.0.0.1:7480", "[::2]:80", "[::1", "", "127.0.0.1.nip.io:7480"})
    EXPECT_FALSE(view::names_this_machine(host)) << host;
  EXPECT_NE(view::handshake_refusal("/ws", "http://evil.example:7480", "evil.example:7480", "")
                .find("evil.example"),
            std::string::npos);
  EXPECT_EQ(view::handshake_refusal("/ws?token=abcdef0123456789abcd", "", "evil.example:7480",
                                    "abcdef0123456789abcd"),
            "")
      << "with a token, the token decides";

  view::ViewServer server(local_options());
  server.publish(view::Channel::scene, "scene");
  server.start();
  const auto upgrade = [&](const std::string& host) {
    return testing::http_exchange(
        "127.0.0.1", server.port(),
        "GET /ws HTTP/1.1\r\nHost: " + host + "\r\nOrigin: http://" + host +
            "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: "
            "dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n",
        true);
  };
  const std::string port = std::to_string(server.port());
  EXPECT_EQ(upgrade("evil.example:" + port).rfind("HTTP/1.1 403", 0), 0u);
  EXPECT_EQ(upgrade("127.0.0.1:" + port).rfind("HTTP/1.1 101", 0), 0u);
  EXPECT_EQ(upgrade("localhost:" + port).rfind("HTTP/1.1 101", 0), 0u);
  EXPECT_EQ(server.counters().refused, 1u);
}

// Nobody makes the server buffer a body (a GET has none), and browsers are capped.
TEST(ViewServer, ARequestWithABodyIsRefusedUnreadAndBrowsersBeyondTheCapAreTurnedAway) {
  view::ViewServerOptions options = local_options();
  options.max_browsers = 3;
  view::ViewServer server(options);
  server.publish(view::Channel::scene, "scene");
  server.start();
  const std::string post =
      testing::http_exchange("127.0.0.1", server.port(),
                             "POST / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: "
                             "33554432\r\nConnection: close\r\n\r\n" +
                                 std::string(4096, 'x'));
  EXPECT_EQ(post.rfind("HTTP/1.1 413", 0), 0u) << post.substr(0, 200);
  std::vector<std::unique_ptr<WebSocketClient>> browsers;
  for (int k = 0; k < 3; ++k) {
    browsers.push_back(std::make_unique<WebSocketClient>(data_url(server)));
    ASSERT_TRUE(browsers.back()->wait_open(10s));
  }
  WebSocketClient fourth(data_url(server));
  EXPECT_FALSE(fourth.wait_open(10s));
  EXPECT_EQ(fourth.refused_status(), 503);
  browsers.pop_back();  // one leaves: another may come
  ASSERT_TRUE(
      testing::wait_until([&] { return server.counters().browsers == 2; }, "the browser to leave"));
  WebSocketClient fifth(data_url(server));
  EXPECT_TRUE(fifth.wait_open(10s));
}

TEST(ViewServer, AMalformedOrOversizedMessageClosesThatBrowserAndNothingElse) {
  std::vector<view::Command> received;
  std::mutex mutex;
  view::ViewServer server(local_options(), [&](const view::Command& command) {
    std::lock_guard lock(mutex);
    received.push_back(command);
  });
  server.publish(view::Channel::scene, "scene");
  server.start();
  WebSocketClient oversized(data_url(server)), text(data_url(server)), garbage(data_url(server)),
      empty(data_url(server)), good(data_url(server));
  for (WebSocketClient* browser : {&oversized, &text, &garbage, &empty, &good})
    ASSERT_TRUE(browser->wait_open(10s));
  view::Command seek;
  seek.set_seek(2.5);
  oversized.send_binary(std::string(2000, '\x22'));  // over the 1024-byte limit
  text.send_text(seek.SerializeAsString());
  garbage.send_binary("\xff\xff\xff\xff");
  empty.send_binary(view::Command().SerializeAsString());  // parses, but says nothing
  good.send_binary(seek.SerializeAsString());
  for (WebSocketClient* browser : {&oversized, &text, &garbage, &empty})
    EXPECT_TRUE(browser->wait_closed(10s));
  EXPECT_EQ(oversized.close_code(), 1009);  // message too big
  EXPECT_EQ(text.close_code(), 1007);       // invalid payload
  EXPECT_EQ(garbage.close_code(), 1007);
  EXPECT_EQ(empty.close_code(), 1007);
  server.publish(view::Channel::frame, "after");
  ASSERT_TRUE(good.wait_messages(2, 10s));
  EXPECT_EQ(good.messages().back(), "after");
  EXPECT_EQ(good.close_code(), 0);
  std::lock_guard lock(mutex);
  ASSERT_EQ(received.size(), 1u);
  EXPECT_EQ(received.front().seek(), 2.5);
  EXPECT_EQ(server.counters().closed_for_bad_message,
            3u);  // the oversized one websocketpp closes itself
}

// A view server that skips a browser with more than 64 kB waiting for it, its scene
// published, and a browser connected to it that does not read (until told to).
class ViewServerWithAStalledBrowser : public ::testing::Test {
 protected:
  static view::ViewServerOptions small_queue_options() {
    view::ViewServerOptions options = local_options();
    options.max_buffered_bytes = 64 * 1024;
    return options;
  }
  void SetUp() override {
    server.publish(view::Channel::scene, "scene");
    server.start();
    stalled.emplace("127.0.0.1", server.port());
    ASSERT_TRUE(stalled->upgraded());
  }

  view::ViewServer server{small_queue_options()};
  std::optional<testing::StalledWebSocket> stalled;
};

TEST_F(ViewServerWithAStalledBrowser, ItGetsNothingNewWhileItsQueueIsFullAndTheOthersGetTheNewest) {
  WebSocketClient reader(data_url(server));
  ASSERT_TRUE(reader.wait_open(10s));
  reader.count_only();  // 40 MB
  constexpr int kFrames = 400;
  const std::string payload(100 * 1024, 'x');  // 40 MB in all
  for (int k = 1; k <= kFrames; ++k) {
    server.publish(view::Channel::frame, std::to_string(k) + payload);
    std::this_thread::sleep_for(1ms);  // a frame rate, so that the reader gets many of them
  }
  server.publish(view::Channel::frame, "last");
  // The reader ends with the newest frame; the stalled browser took what the kernel's socket
  // buffers hold and then nothing: far fewer than were published, however many were.
  ASSERT_TRUE(testing::wait_until([&] { return reader.last_message() == "last"; },
                                  "the newest frame at the reader"));
  const view::ViewCounters counters = server.counters();
  const std::uint64_t to_stalled = counters.messages_sent - reader.message_count();
  std::printf(
      "  published %d frames of 100 kB: the reader got %zu, the stalled browser %llu; %llu "
      "dropped\n",
      kFrames + 1, reader.message_count(), static_cast<unsigned long long>(to_stalled),
      static_cast<unsigned long long>(counters.dropped));
  EXPECT_LT(to_stalled, static_cast<std::uint64_t>(kFrames / 4));
  EXPECT_GT(counters.dropped, static_cast<std::uint64_t>(kFrames / 2));
}

// A browser skipped while its queue is full gets the newest frame once it reads again, though
// nothing more is published.
TEST_F(ViewServerWithAStalledBrowser, OnceItReadsAgainItGetsTheNewest) {
  const std::string payload(100 * 1024, 'x');  // 3 MB in all: more than its socket holds
  for (int k = 1; k <= 30; ++k) {
    server.publish(view::Channel::frame, std::to_string(k) + payload);
    std::this_thread::sleep_for(1ms);
  }
  server.publish(view::Channel::frame, "last");
  std::this_thread::sleep_for(100ms);  // "last" finds the browser busy
  EXPECT_TRUE(stalled->read_until_message("last", 10s));
  EXPECT_GT(server.counters().dropped, 0u);  // it was skipped: frames were dropped for it
}

// As many browsers as the server takes, none reading, while 1 MB frames are published: each
// frame is held once for all of them, so the server's memory grows by a few frames, not by
// a queue per browser (64 queues of 2 MB and more, were each frame copied per browser).
TEST(ViewServer, BrowsersThatStopReadingShareOneCopyOfEachFrame) {
#ifdef COHAPTIC_SANITIZER_OWNS_MALLOC
  GTEST_SKIP() << "the sanitizer's allocator keeps freed blocks in quarantine, and the resident "
                  "set counts them: "
                  "the plain build measures";
#endif
  view::ViewServerOptions options = local_options();
  view::ViewServer server(options);
  server.publish(view::Channel::scene, "scene");
  server.start();
  std::vector<std::unique_ptr<testing::StalledWebSocket>> stalled;
  for (int k = 0; k < options.max_browsers; ++k) {
    stalled.push_back(std::make_unique<testing::StalledWebSocket>("127.0.0.1", server.port()));
    ASSERT_TRUE(stalled.back()->upgraded());
  }
  ASSERT_TRUE(testing::wait_until(
      [&] { return server.counters().browsers == options.max_browsers; }, "every browser"));
  const std::size_t rss_before = testing::usage_of(getpid()).value().rss_bytes;
  constexpr int kFrames = 40;
  for (int k = 1; k <= kFrames; ++k) {
    server.publish(view::Channel::frame, std::to_string(k) + std::string(1 << 20, 'x'));
    std::this_thread::sleep_for(20ms);
  }
  std::this_thread::sleep_for(500ms);  // every send the server will make is made
  const std::size_t rss_after = testing::usage_of(getpid()).value().rss_bytes;
  const double grown_mb = (static_cast<double>(rss_after) - static_cast<double>(rss_before)) / 1e6;
  std::printf(
      "  %d browsers not reading, %d frames of 1 MB published: the process grew by %.1f MB; %llu "
      "frames "
      "sent, %llu dropped\n",
      options.max_browsers, kFrames, grown_mb,
      static_cast<unsigned long long>(server.counters().messages_sent),
      static_cast<unsigned long long>(server.counters().dropped));
  EXPECT_GE(server.counters().messages_sent, static_cast<std::uint64_t>(2 * options.max_browsers))
      << "frames were sent";
  EXPECT_LT(grown_mb, 48.0);
}

// ---- the recording's player ----

// Frames every 0.1 s from t = 1: user 0's force rises by 0.1 N a frame to 1 N (the peak,
// first reached at t = 2), holds, then drops to 0.2 N at t = 2.5 (the largest step);
// user 1 is absent. Two status reports of user 0, at 1.25 s and 2.05 s.
record::Recording made_up_recording() {
  record::Recording recording;
  recording.file = "made-up.mcap";
  recording.config.set_start_time_ns(1'000'000'000);
  view::Scene& scene = recording.view_scenes.emplace_back();
  for (std::uint32_t slot : {0u, 1u}) scene.add_tools()->set_slot(slot);
  for (int k = 0; k <= 20; ++k) {
    view::Frame& frame = recording.view_frames.emplace_back();
    frame.set_time(1.0 + 0.1 * k);
    frame.set_sequence(static_cast<std::uint64_t>(k + 1));
    const double force = k <= 10 ? 0.1 * k : (k < 15 ? 1.0 : 0.2);
    view::UserFrame* user = frame.add_users();
    user->set_slot(0);
    user->set_present(true);
    for (double component : {0.0, 0.0, force}) user->add_force(static_cast<float>(component));
    frame.add_users()->set_slot(1);
  }
  for (double t : {1.25, 2.05}) {
    record::ReceivedClientStatus& status = recording.client_statuses.emplace_back();
    status.set_receive_time_ns(1'000'000'000 + static_cast<std::int64_t>(t * 1e9));
    status.set_slot(0);
    status.set_user("surgeon");
    status.mutable_status()->set_ticks(static_cast<std::uint64_t>(t * 1000));
  }
  return recording;
}

TEST(ReplayPlayer, FindsThePeakAndTheLargestStepSeeksToTheFrameAtATimeAndPlaysAtItsSpeed) {
  view::ReplayPlayer player(made_up_recording());
  EXPECT_NEAR(player.peak_force_time(), 2.0, 1e-12);
  EXPECT_NEAR(player.largest_step_time(), 2.5, 1e-12);
  EXPECT_EQ(player.scene().source(), "made-up.mcap");
  ASSERT_EQ(player.scene().force_series_size(), 2);
  EXPECT_EQ(player.scene().force_series(0).magnitudes_size(), 21);
  EXPECT_NEAR(player.scene().force_series(0).magnitudes(4), 0.4, 1e-6);

  EXPECT_EQ(player.frame_index(), 0u);
  EXPECT_EQ(player.status().users_size(), 0);  // nothing reported before 1.25 s
  player.seek(1.55);
  EXPECT_EQ(player.frame_index(), 5u);  // the frame at 1.5 s, the last not after 1.55 s
  ASSERT_EQ(player.status().users_size(), 1);
  EXPECT_EQ(player.status().users(0).figures().ticks(), 1250u);
  player.seek(99);
  EXPECT_EQ(player.frame_index(), 20u);
  EXPECT_EQ(player.status().users(0).figures().ticks(), 2050u);
  player.seek(-5);
  EXPECT_EQ(player.frame_index(), 0u);

  view::Command command;
  command.set_jump(view::Command::LARGEST_STEP);
  player.command(command);
  EXPECT_NEAR(player.frame().time(), 2.5, 1e-12);
  command.set_jump(view::Command::PEAK_FORCE);
  player.command(command);
  EXPECT_NEAR(player.frame().time(), 2.0, 1e-12);

  command.set_speed(-1);  // ignored
  player.command(command);
  command.set_speed(2);
  player.command(command);
  player.advance(0.1);  // paused: nothing moves
  EXPECT_NEAR(player.time(), 2.0, 1e-12);
  command.mutable_play();
  player.command(command);
  player.advance(0.1);
  EXPECT_NEAR(player.time(), 2.2, 1e-9);
  EXPECT_EQ(player.timeline().speed(), 2);
  EXPECT_TRUE(player.timeline().playing());
  for (double wall : {std::nan(""), -1.0, 0.0}) {  // ignored: the position stays in the recording
    player.advance(wall);
    player.seek(std::nan(""));
    EXPECT_NEAR(player.time(), 2.2, 1e-9) << wall;
  }
  player.advance(10);  // past the end: it stops there
  EXPECT_NEAR(player.time(), 3.0, 1e-12);
  EXPECT_FALSE(player.playing());
  player.command(command);  // play at the end starts again from the beginning
  EXPECT_NEAR(player.time(), 1.0, 1e-12);
  EXPECT_TRUE(player.playing());
}

TEST(ReplayPlayer, ARecordingWithoutViewFramesIsRefusedSayingHowToRecordOne) {
  record::Recording recording;
  recording.file = "plain.mcap";
  try {
    view::ReplayPlayer player(recording);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("plain.mcap"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("--view"), std::string::npos);
  }
}

// ---- a frame, from the simulation ----

// A soft cube pressed 2 mm into its top face by tool 0, with 12 step-delay nodes held: loads
// on the contact triangle and on the held nodes.
struct PressedCube {
  testing::CubeRig cube;
  Simulation simulation;
  const Eigen::Vector3d pressing{0.003, 0.002, -0.002};
  static testing::CubeSceneOptions soft() {
    testing::CubeSceneOptions soft;
    soft.divisions = 6;
    soft.youngs_modulus = 2.0e4;
    soft.touchable = "{surface: true}";
    return soft;
  }
  static SimulationOptions options(const Model& model) {
    SimulationOptions options;
    options.ir = ir_build_options(model.scene.haptic);
    options.step_delay_nodes = 12;
    return options;
  }
  PressedCube()
      : cube(soft()),
        simulation(cube.body, cube.model->obstacles, *cube.columns, cube.model->scene.tools,
                   options(*cube.model)) {
    simulation.set_tool(0, pressing);
    simulation.step(0);
    simulation.step(0.001);
  }
};

// ---- the state's loads, for the view's thread ----

TEST(LoadedColumns, GiveTheDisplacementOfTheGatheredComplianceAndRefuseAPositionOutsideTheRows) {
  PressedCube pressed;
  ASSERT_TRUE(pressed.simulation.pressing(0));
  ComplianceColumns& columns = *pressed.cube.columns;
  const StateSolution state = pressed.simulation.solve();
  ASSERT_FALSE(state.contact_dofs.empty());
  ASSERT_FALSE(state.boundary_dofs.empty());
  const std::vector<LoadedColumn> loads = loaded_columns(columns, state);
  EXPECT_EQ(loads.size(), state.contact_dofs.size() + state.boundary_dofs.size());
  // Every row node, in a shuffled order: against L[rows, dofs] f gathered as a block.
  std::vector<int> nodes = columns.row_nodes();
  std::reverse(nodes.begin(), nodes.end());
  std::vector<int> positions;
  for (int node : nodes) positions.push_back(columns.row_position(node));
  const Eigen::Matrix3Xd expected = displacement_of_nodes(columns, state, nodes);
  const Eigen::Matrix3Xd u = displacement_of_rows(loads, positions);
  ASSERT_EQ(u.cols(), expected.cols());
  EXPECT_GT(expected.colwise().norm().maxCoeff(), 1e-3);  // the 2 mm press moves the surface
  EXPECT_LT((u - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());

  const std::vector<int> outside = {columns.volume_node_count()};
  try {
    displacement_of_rows(loads, outside);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(columns.volume_node_count())),
              std::string::npos)
        << e.what();
  }
}

// ---- a frame, from the simulation ----

TEST(ViewFrame, CarriesTheSimulationsDisplacementForcesPatchContactAndHeldNodes) {
  // The pressed cube's press, stepped by a scene simulation as the server steps it.
  PressedCube pressed;
  testing::CubeRig& cube = pressed.cube;
  const std::array columns{cube.columns.get()};
  SceneSimulation scene(*cube.model, columns, cube.model->scene.tools,
                        PressedCube::options(*cube.model));
  const Eigen::Vector3d pressing = pressed.pressing;
  scene.set_tool(0, pressing);
  scene.step(0);
  scene.step(0.001);
  Simulation& simulation = scene.single_elastic();
  ASSERT_TRUE(simulation.pressing(0));

  const view::ShownScene shown_scene = view::shown_scene(*cube.model, columns);
  ASSERT_EQ(shown_scene.parts.size(), 1u);
  const ShownSurface shown = shown_surface(cube.body, cube.columns->row_nodes());
  EXPECT_EQ(shown_scene.parts[0].nodes, shown.nodes);
  EXPECT_EQ(shown_scene.triangles, shown.triangles);
  const std::vector<view::ToolState> tools = {{true, pressing}, {false, Eigen::Vector3d::Zero()}};
  const std::vector<Eigen::Vector3d> forces = {simulation.force(0).force, Eigen::Vector3d::Zero()};
  const view::FrameState state =
      view::frame_state(scene, columns, solve_elastic_states(scene), tools, forces);
  const view::Frame frame = view::view_frame(state, shown_scene, 7, 0.001, 999);
  EXPECT_EQ(frame.sequence(), 7u);
  EXPECT_EQ(frame.time(), 0.001);
  EXPECT_EQ(frame.sim_rate_hz(), 999.0);
  // The shown nodes' displacement, as the simulation solves it for the display (in float).
  const Eigen::Matrix3Xd displacement = simulation.displacement_of(shown.nodes);
  const double largest = displacement.cwiseAbs().maxCoeff();
  ASSERT_EQ(frame.displacement_size(), displacement.size());
  for (Eigen::Index i = 0; i < displacement.size(); ++i)
    ASSERT_NEAR(frame.displacement(static_cast<int>(i)), displacement.data()[i], 1e-6 * largest)
        << i;
  ASSERT_EQ(frame.users_size(), 2);
  const view::UserFrame& user = frame.users(0);
  EXPECT_TRUE(user.present());
  EXPECT_TRUE(user.pressing());
  const Eigen::Vector3d force = simulation.force(0).force;
  EXPECT_GT(force.norm(), 0.01);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_EQ(user.force(axis), static_cast<float>(force[axis]));
    EXPECT_EQ(user.position(axis), static_cast<float>(pressing[axis]));
  }
  // The contact triangle is the IR's first patch triangle, its nodes mapped to the shown
  // surface's; every patch node is shown (the whole surface has rows).
  const CondensedFemIr& ir = condensed_fem(simulation.ir(0)->ir);
  ASSERT_EQ(user.contact_nodes_size(), 3);
  for (int corner = 0; corner < 3; ++corner) {
    const int shown_node = static_cast<int>(user.contact_nodes(corner));
    const int volume_node = shown.nodes[static_cast<std::size_t>(shown_node)];
    EXPECT_EQ(cube.body.mesh.node_tags[static_cast<std::size_t>(volume_node)],
              ir.node_ids[static_cast<std::size_t>(
                  ir.patch.front().nodes[static_cast<std::size_t>(corner)])]);
  }
  EXPECT_EQ(user.patch_nodes_size(), ir.patch_node_count);
  EXPECT_FALSE(frame.users(1).present());
  EXPECT_EQ(frame.users(1).force_size(), 0);
  // The held step-delay nodes, all on the surface.
  EXPECT_EQ(frame.boundary_nodes(), 12u);
  ASSERT_EQ(frame.held_nodes_size(), 12);
  for (std::uint32_t held : frame.held_nodes())
    EXPECT_NE(std::find(simulation.condensation().boundary_nodes().begin(),
                        simulation.condensation().boundary_nodes().end(), shown.nodes[held]),
              simulation.condensation().boundary_nodes().end());
}

// ---- the live view on the server's loop ----

// The server's loop on the pressed cube with a live view, stepped by hand at 1 ms a step:
// the same state as `pressed`'s simulation.
struct ViewedLoop {
  static ServeOptions like_pressed() {
    ServeOptions options;
    options.step_nodes = 12;
    return options;
  }
  PressedCube pressed;
  ServeOptions options = like_pressed();
  ToolInputs tools{pressed.cube.model->scene.tools.size()};
  LoopStatistics statistics;
  std::int64_t now_ns = monotonic_now_ns();  // before `loop`, which starts its clock at it
  view::LiveView live;
  SimulationLoop loop;
  explicit ViewedLoop(record::SessionRecorder* recorder)
      : live(*pressed.cube.model, std::array{pressed.cube.columns.get()}, wire::P0, {}, {},
             recorder),
        loop(*pressed.cube.model, std::array{pressed.cube.columns.get()}, options, tools,
             statistics, nullptr, &live, recorder, now_ns) {
    tools.join(0);
    live.start();
  }
  void run(double seconds) {
    for (int k = 0; k < static_cast<int>(seconds * 1000); ++k) {
      now_ns += 1'000'000;
      tools.update(0, true, pressed.pressing, 0, now_ns, now_ns);
      loop.step(now_ns);
    }
  }
};

TEST(LiveView, BuildsNoFrameWhileNobodyWatchesAndTheSimulationsStateForABrowser) {
  ViewedLoop session(nullptr);
  session.run(0.5);  // 15 frame periods
  EXPECT_EQ(session.live.frames_built(), 0u);

  auto browser = std::make_unique<WebSocketClient>(
      "ws://127.0.0.1:" + std::to_string(session.live.port()) + "/ws");
  ASSERT_TRUE(browser->wait_open(testing::kPatience));
  ASSERT_TRUE(testing::wait_until([&] { return session.live.counters().browsers == 1; },
                                  "the browser counted"));
  session.run(0.2);
  ASSERT_TRUE(
      testing::wait_until([&] { return browser->message_count() >= 2; }, "the scene and a frame"));
  EXPECT_GE(session.live.frames_built(), 1u);
  EXPECT_LE(session.live.frames_built(), 7u);  // at most one per 1/30 s of the 0.2 s stepped
  view::ServerMessage message;
  ASSERT_TRUE(message.ParseFromString(browser->last_message()));
  ASSERT_TRUE(message.has_frame());
  const view::Frame& frame = message.frame();
  // The state the loop stepped: tool 0 pressing where it was put, the surface pressed as a
  // simulation of its own solves it.
  ASSERT_EQ(frame.users_size(), 2);
  EXPECT_TRUE(frame.users(0).present());
  EXPECT_TRUE(frame.users(0).pressing());
  EXPECT_FALSE(frame.users(1).present());
  EXPECT_EQ(frame.users(0).position(2), static_cast<float>(session.pressed.pressing.z()));
  const ShownSurface shown =
      shown_surface(session.pressed.cube.body, session.pressed.cube.columns->row_nodes());
  const Eigen::Matrix3Xd expected = session.pressed.simulation.displacement_of(shown.nodes);
  ASSERT_EQ(frame.displacement_size(), expected.size());
  double largest = 0;
  for (float each : frame.displacement())
    largest = std::max(largest, std::abs(static_cast<double>(each)));
  EXPECT_NEAR(largest, expected.cwiseAbs().maxCoeff(), 1e-5 * largest);

  // Gone again: no more frames.
  browser.reset();
  ASSERT_TRUE(testing::wait_until([&] { return session.live.counters().browsers == 0; },
                                  "the browser gone"));
  const std::uint64_t built = session.live.frames_built();
  session.run(0.5);
  EXPECT_EQ(session.live.frames_built(), built);
  session.live.stop();
}

TEST(LiveView, ARecordedSessionGetsItsFramesWithoutABrowser) {
  const std::filesystem::path file =
      testing::scratch_directory("live_view_recorded") / "server.mcap";
  {
    record::SessionRecorder recorder(file);
    ViewedLoop session(&recorder);
    // A frame period at a time (33 steps of 1 ms, one frame due in each), each frame built
    // before the next is due: stepped faster than real time, a state the view's thread has
    // not taken yet would be replaced by the newer.
    for (std::uint64_t frame = 1; frame <= 15; ++frame) {
      session.run(0.033);
      ASSERT_TRUE(testing::wait_until([&] { return session.live.frames_built() == frame; },
                                      "the period's frame"));
    }
    session.live.stop();
    recorder.close();
  }
  const record::Recording recording = record::read_recording(file);
  ASSERT_EQ(recording.view_frames.size(), 15u);
  for (std::size_t k = 1; k < recording.view_frames.size(); ++k)
    EXPECT_EQ(recording.view_frames[k].sequence(), recording.view_frames[k - 1].sequence() + 1);
  EXPECT_TRUE(recording.view_frames.back().users(0).pressing());
}

}  // namespace
}  // namespace cohaptic
