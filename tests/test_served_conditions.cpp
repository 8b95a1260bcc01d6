// Conditions a session switches between while it runs: their command-line form is parsed and
// checked (errors name the text and the key), a switch names a known condition, the control
// socket answers each line and survives bad ones, a link's delay changes without losing its
// order, and a simulation's held nodes follow a new step-delay count at its next step.
#include <gtest/gtest.h>

#include <asio.hpp>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "common/delay/link_delay.h"
#include "common/util/error.h"
#include "lab/control_client.h"
#include "server/control_socket.h"
#include "server/served_conditions.h"
#include "support/cube_scene.h"
#include "support/process.h"

namespace cohaptic {
namespace {

std::string parse_error(const std::string& text) {
  try {
    parse_served_condition(text);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(ServedCondition, ParsesItsCommandLineFormAndNamesWhatIsWrong) {
  const ServedCondition c = parse_served_condition(
      "slow:protocol=P0,shift_ms=30,jitter_ms=2,loss=0.1,step_nodes=150,sim_rate_hz=40");
  EXPECT_EQ(c.name, "slow");
  EXPECT_EQ(c.protocol, ServeProtocol::p0);
  EXPECT_EQ(c.shift_delay_ms, 30);
  EXPECT_EQ(c.jitter_ms, 2);
  EXPECT_EQ(c.loss, 0.1);
  EXPECT_EQ(c.step_nodes, 150);
  EXPECT_EQ(c.sim_rate_hz, 40);
  EXPECT_EQ(c.describe(),
            "P0, shift 30 ms, jitter 2 ms, loss 0.1, 150 held nodes, simulation capped at 40 Hz");
  LinkDelaySettings session;
  session.reorder = 0.05;
  session.seed = 9;
  const LinkDelaySettings link = c.link_delay(session);
  EXPECT_EQ(link.delay_ms, 30);
  EXPECT_EQ(link.reorder, 0.05) << "reorder and seed stay the session's";
  EXPECT_EQ(link.seed, 9u);
  const ServedCondition plain = parse_served_condition("plain");
  EXPECT_EQ(plain.protocol, ServeProtocol::p1);
  EXPECT_EQ(plain.describe(), "P1");

  EXPECT_NE(parse_error(":protocol=P1").find("no name"), std::string::npos);
  EXPECT_NE(parse_error("a:protocol=P2").find("protocol=P2 is neither P0 nor P1"),
            std::string::npos);
  EXPECT_NE(parse_error("a:shift_ms=-1").find("shift_ms=-1 is not a delay"), std::string::npos);
  EXPECT_NE(parse_error("a:loss=1").find("loss=1 is not a probability"), std::string::npos);
  EXPECT_NE(parse_error("a:step_nodes=1.5").find("not a whole number"), std::string::npos);
  EXPECT_NE(parse_error("a:speed=3").find("unknown key speed"), std::string::npos);
  EXPECT_NE(parse_error("a:shift_ms").find("'shift_ms' is not key=value"), std::string::npos);
  EXPECT_NE(parse_error("a:shift_ms=1,shift_ms=2").find("shift_ms is given twice"),
            std::string::npos);
  EXPECT_NE(parse_error("a:shift_ms=1x").find("--condition 'a:shift_ms=1x'"), std::string::npos);
}

TEST(ConditionSwitch, ServesAKnownConditionOrTheNextAndCountsTheSwitches) {
  ServedCondition a, b;
  a.name = "A";
  b.name = "B";
  ConditionSwitch conditions({a, b});
  EXPECT_EQ(conditions.served().index, 0);
  EXPECT_EQ(conditions.served().switches, 0u);
  EXPECT_EQ(conditions.serve("B"), 1);
  EXPECT_EQ(conditions.serve("B"), 1);
  EXPECT_EQ(conditions.served().index, 1);
  EXPECT_EQ(conditions.served().switches, 2u);
  try {
    conditions.serve("C");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no condition named 'C' (this session serves A, B)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(conditions.served().index, 1) << "an unknown name switches nothing";
  EXPECT_EQ(conditions.serve_next(), 0) << "after the last, the first";
  EXPECT_EQ(conditions.serve_next(), 1);
  EXPECT_EQ(conditions.served().switches, 4u);
  EXPECT_THROW(ConditionSwitch({a, a}), Error);
  EXPECT_THROW(ConditionSwitch({}), Error);
}

TEST(ControlSocket, AnswersEachLineAndSurvivesBadOnes) {
  const std::filesystem::path dir = testing::scratch_directory("control-socket");
  const std::filesystem::path path = dir / "control";
  asio::io_context io;
  std::vector<std::string> served;
  ControlSocket control(io, path, [&](const nlohmann::json& command) -> nlohmann::json {
    if (!command.contains("serve")) throw Error("unknown command");
    served.push_back(command["serve"].get<std::string>());
    return {{"served", served.back()}};
  });
  EXPECT_EQ(std::filesystem::status(path).permissions() & std::filesystem::perms::others_all,
            std::filesystem::perms::none)
      << "only the server's user may connect";
  std::thread io_thread([&] { io.run(); });
  {
    ControlClient client(path);
    EXPECT_EQ(client.ask_line(R"({"serve": "B"})"), (nlohmann::json{{"served", "B"}}));
    EXPECT_EQ(client.ask_line("not json").at("error"),
              "not a JSON object on one line, e.g. {\"serve\": \"B\"}");
    EXPECT_EQ(client.ask_line(R"({"foo": 1})").at("error"), "unknown command");
    EXPECT_EQ(client.serve("A"), (nlohmann::json{{"served", "A"}})) << "the connection stays open";
    ControlClient second(path);
    EXPECT_EQ(second.ask({{"serve", "B"}}), (nlohmann::json{{"served", "B"}}));
    // A line over 4 KiB is answered, and the connection closed.
    const nlohmann::json reply = client.ask_line(std::string(5000, 'x'));
    EXPECT_NE(reply.at("error").get<std::string>().find("at most 4096 bytes"), std::string::npos)
        << reply;
  }
  asio::post(io, [&] { control.close(); });
  io_thread.join();  // nothing left to do once the socket is closed
  EXPECT_EQ(served, (std::vector<std::string>{"B", "A", "B"}));
  EXPECT_FALSE(std::filesystem::exists(path)) << "the socket file is removed on close";

  // A path that is another kind of file is refused, naming it; a stale socket is replaced.
  std::ofstream(dir / "file") << "x";
  asio::io_context again;
  try {
    ControlSocket refused(again, dir / "file",
                          [](const nlohmann::json&) { return nlohmann::json(); });
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("exists and is not a socket"), std::string::npos)
        << e.what();
  }
  {
    asio::local::stream_protocol::acceptor stale(
        again, asio::local::stream_protocol::endpoint(path.string()));
  }
  EXPECT_NO_THROW(
      ControlSocket(again, path, [](const nlohmann::json&) { return nlohmann::json(); }));
}

TEST(LinkDelay, NewSettingsApplyFromTheNextMessageAndAnOrderedLinkKeepsItsOrder) {
  LinkDelaySettings slow;
  slow.delay_ms = 50;
  LinkDelay link(slow, true);
  const std::int64_t first = *link.delay_ns(0);
  EXPECT_EQ(first, 50'000'000);
  LinkDelaySettings fast;
  link.set_settings(fast);
  // Sent 1 ms later with no delay, it may not overtake the first on an ordered link.
  const std::int64_t second = *link.delay_ns(1'000'000);
  EXPECT_GT(1'000'000 + second, first);
  const std::int64_t later = *link.delay_ns(100'000'000);
  EXPECT_EQ(later, 0) << "the new delay, once the order allows";
  EXPECT_EQ(link.counters().messages, 3u);
  LinkDelaySettings bad;
  bad.loss = 2;
  EXPECT_THROW(link.set_settings(bad), Error);
}

}  // namespace
}  // namespace cohaptic
