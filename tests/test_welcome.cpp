// The client's checks of the server's Welcome (client/welcome.h): a correct welcome is
// taken field by field; each value a correct server never sends is refused, naming the
// field. Against the scene's own ranges (load_scene.cpp) and the haptic loop's needs.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "client/welcome.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

using ::testing::HasSubstr;

wire::Welcome correct_welcome() {
  wire::Welcome welcome;
  welcome.set_slot(1);
  welcome.set_scene_name("cube");
  welcome.set_scene_yaml("name: cube\n");
  welcome.set_protocol(wire::P0);
  welcome.set_force_limit(3.3);
  welcome.set_haptic_rate_hz(1000);
  welcome.set_ir_max_age_s(0.5);
  for (int slot = 0; slot < 2; ++slot)
    welcome.add_users()->set_slot(static_cast<std::uint32_t>(slot));
  return welcome;
}

TEST(Welcome, ACorrectWelcomeIsTakenFieldByField) {
  const WelcomeInfo info = welcome_info(correct_welcome());
  EXPECT_EQ(info.slot, 1);
  EXPECT_EQ(info.scene_name, "cube");
  EXPECT_EQ(info.scene_yaml, "name: cube\n");
  EXPECT_EQ(info.protocol, HapticProtocol::p0);
  EXPECT_EQ(info.force_limit, 3.3);
  EXPECT_EQ(info.haptic_rate_hz, 1000);
  EXPECT_EQ(info.ir_max_age_s, 0.5);
  EXPECT_EQ(info.user_count, 2);
}

TEST(Welcome, ValuesACorrectServerNeverSendsAreRefusedByName) {
  const double nan = std::numeric_limits<double>::quiet_NaN(),
               inf = std::numeric_limits<double>::infinity();
  struct Case {
    std::function<void(wire::Welcome&)> change;
    std::string named;
  };
  const std::vector<Case> cases{
      {[](wire::Welcome& w) { w.set_slot(2); }, "slot 2 is not one of its 2 user slots"},
      {[](wire::Welcome& w) { w.set_protocol(wire::PROTOCOL_UNSPECIFIED); }, "protocol 0"},
      // A NaN limit would switch the haptic loop's limiting off (NaN compares false).
      {[nan](wire::Welcome& w) { w.set_force_limit(nan); }, "force_limit nan"},
      {[inf](wire::Welcome& w) { w.set_force_limit(inf); }, "force_limit inf"},
      {[](wire::Welcome& w) { w.set_force_limit(0); }, "force_limit 0"},
      {[](wire::Welcome& w) { w.set_force_limit(-1); }, "force_limit -1"},
      // A zero rate would make the loop's period 1e9 / 0.
      {[](wire::Welcome& w) { w.set_haptic_rate_hz(0); }, "haptic_rate_hz 0"},
      {[](wire::Welcome& w) { w.set_haptic_rate_hz(1e6); }, "haptic_rate_hz 1000000"},
      {[nan](wire::Welcome& w) { w.set_haptic_rate_hz(nan); }, "haptic_rate_hz nan"},
      {[](wire::Welcome& w) { w.set_ir_max_age_s(-0.5); }, "ir_max_age_s -0.5"},
      {[inf](wire::Welcome& w) { w.set_ir_max_age_s(inf); }, "ir_max_age_s inf"},
  };
  for (const Case& c : cases) {
    wire::Welcome welcome = correct_welcome();
    c.change(welcome);
    try {
      welcome_info(welcome);
      ADD_FAILURE() << c.named << ": accepted";
    } catch (const Error& e) {
      EXPECT_THAT(e.what(), HasSubstr("welcome from the server: " + c.named)) << c.named;
    }
  }
}

}  // namespace
}  // namespace cohaptic
