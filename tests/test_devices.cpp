// Haptic devices (client/device/): scripted trajectories against positions computed by
// hand, their YAML errors (file, line, key path), the closed-loop hand model against the
// closed-form damped oscillator, its steady state and energy, a virtual wall on either side
// of the Colgate-Schenkel passivity bound, and the UDP bridge in real round trips on
// 127.0.0.1 (newest pose wins, bad packets dropped and counted, timeout, force packets).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <new>
#include <numbers>
#include <cstdio>
#include <string>
#include <vector>

#include "client/device/bridge_device.h"
#include "client/device/bridge_peer.h"
#include "client/device/bridge_protocol.h"
#include "client/device/make_device.h"
#include "common/haptics/hand_model.h"
#include "common/haptics/scripted_device.h"
#include "common/haptics/trajectory.h"
#include "common/util/error.h"
#include "support/sanitizer_owns_malloc.h"
#include "support/wait.h"

// Counting operator new, for the "no allocation in the haptic thread" checks. Weak, so that
// another test file's replacement (if one appears) wins without a link error; the tests
// then skip after checking the counter sees a known allocation.
namespace {
std::atomic<bool> g_count_new{false};
std::atomic<long> g_new_calls{0};
}  // namespace

#ifndef COHAPTIC_SANITIZER_OWNS_MALLOC
__attribute__((weak)) void* operator new(std::size_t size) {
  if (g_count_new.load(std::memory_order_relaxed))
    g_new_calls.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
__attribute__((weak)) void* operator new[](std::size_t size) {
  if (g_count_new.load(std::memory_order_relaxed))
    g_new_calls.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
#endif

namespace cohaptic {
namespace {

const std::string kDataDir = std::string(COHAPTIC_SOURCE_DIR) + "/tests/data/devices/";
constexpr double kMm = 1e-3;

/// Runs `body` while counting operator new calls; returns how many there were, or -1 if the
/// counter is not active in this program (checked with a known allocation first).
long count_allocations(const std::function<void()>& body) {
  g_new_calls = 0;
  g_count_new = true;
  {
    volatile auto* probe = new std::vector<int>(10);
    delete probe;
  }
  g_count_new = false;
  if (g_new_calls.load() == 0) return -1;
  g_new_calls = 0;
  g_count_new = true;
  body();
  g_count_new = false;
  return g_new_calls.load();
}

void expect_near(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected, double tolerance,
                 const std::string& what) {
  EXPECT_LE((actual - expected).norm(), tolerance)
      << what << ": actual [" << actual.transpose() << "], expected [" << expected.transpose()
      << "]";
}

// ---------------------------------------------------------------------------------------
// Trajectories

// The example. By hand, in mm and s (rows: segment, end time, end point):
//   repetition 1: move_to 18 mm at 20 -> 0.9 (0,0,2); press 15 at 5 -> 3.9 (0,0,-13);
//     hold -> 4.9; release 15 at 5 -> 7.9 (0,0,2); move_by 10 at 10 -> 8.9 (10,0,2)
//   repetition 2: move_to 10 mm at 20 -> 9.4 (0,0,2); 12.4; 13.4; 16.4; 17.4 (10,0,2)
//   repetition 3: 17.9; 20.9; 21.9; 24.9; 25.9 (10,0,2)
const std::string kExample = R"(units: mm
start: [0, 0, 20]
segments:
  - {move_to: [0, 0, 2], speed: 20}
  - {press: 15, speed: 5, direction: [0, 0, -1]}
  - {hold: 1.0}
  - {release: 15, speed: 5}
  - {move_by: [10, 0, 0], speed: 10}
repeat: 3
)";

TEST(Trajectory, ExamplePositionsAndVelocitiesByHand) {
  const Trajectory tr = parse_trajectory(kExample, "example.yaml");
  EXPECT_NEAR(tr.duration(), 25.9, 1e-12);
  const double tol = 1e-12;
  struct Expect {
    double t;
    Eigen::Vector3d p_mm, v_mm_s;
  };
  const std::vector<Expect> expected{
      {-1.0, {0, 0, 20}, {0, 0, 0}},    // before the start
      {0.0, {0, 0, 20}, {0, 0, -20}},   // t = 0: start, moving
      {0.45, {0, 0, 11}, {0, 0, -20}},  // half way down the approach
      {2.4, {0, 0, -5.5}, {0, 0, -5}},  // 1.5 s into the press: 7.5 mm below 2
      {4.0, {0, 0, -13}, {0, 0, 0}},    // holding at the bottom
      {6.4, {0, 0, -5.5}, {0, 0, 5}},   // releasing: back up along +z
      {8.4, {5, 0, 2}, {10, 0, 0}},     // move_by half way
      {9.15, {5, 0, 2}, {-20, 0, 0}},   // repetition 2 starts where 1 ended: move_to back
      {11.4, {0, 0, -8}, {0, 0, -5}},   // repetition 2, 2 s into the press
      {25.4, {5, 0, 2}, {10, 0, 0}},    // repetition 3, last move_by
      {25.9, {10, 0, 2}, {0, 0, 0}},    // the end
      {1e6, {10, 0, 2}, {0, 0, 0}},     // long after
  };
  for (const auto& e : expected) {
    expect_near(tr.position(e.t), e.p_mm * kMm, tol, "position at t = " + std::to_string(e.t));
    expect_near(tr.velocity(e.t), e.v_mm_s * kMm, tol, "velocity at t = " + std::to_string(e.t));
  }
  // Knot times, all of them.
  const std::vector<double> times{0,    0.9,  3.9,  4.9,  7.9,  8.9,  9.4,  12.4,
                                  13.4, 16.4, 17.4, 17.9, 20.9, 21.9, 24.9, 25.9};
  ASSERT_EQ(tr.knot_times().size(), times.size());
  for (std::size_t i = 0; i < times.size(); ++i)
    EXPECT_NEAR(tr.knot_times()[i], times[i], 1e-12) << "knot " << i;
  EXPECT_TRUE(std::isfinite(tr.position(std::numeric_limits<double>::quiet_NaN()).norm()));
}

TEST(Trajectory, ReleaseGoesBackAlongTheLastPressDirection) {
  const Trajectory tr = parse_trajectory(R"(units: cm
start: [1, 2, 3]
segments:
  - {press: 1, speed: 0.5, direction: [3, 4, 0]}
  - {release: 0.4, speed: 0.5}
  - {press: 0.2, speed: 0.1}
)",
                                         "diagonal.yaml");
  // direction (0.6, 0.8, 0); press 1 cm in 2 s; release 0.4 cm in 0.8 s; the third segment
  // has no direction, so it presses along the previous one: 0.2 cm in 2 s.
  const Eigen::Vector3d start(0.01, 0.02, 0.03);
  const Eigen::Vector3d dir(0.6, 0.8, 0.0);
  EXPECT_NEAR(tr.duration(), 4.8, 1e-12);
  expect_near(tr.position(2.0), start + 0.01 * dir, 1e-15, "pressed");
  expect_near(tr.position(2.4), start + 0.008 * dir, 1e-15, "half released");
  expect_near(tr.velocity(2.4), -0.005 * dir, 1e-15, "release velocity");
  expect_near(tr.position(2.8), start + 0.006 * dir, 1e-15, "released");
  expect_near(tr.position(4.8), start + 0.008 * dir, 1e-15,
              "pressed again along the same direction");
  // Without any direction a press goes along -z.
  const Trajectory down =
      parse_trajectory("start: [0, 0, 0]\nsegments: [{press: 0.01, speed: 0.01}]\n", "down.yaml");
  expect_near(down.position(1.0), Eigen::Vector3d(0, 0, -0.01), 1e-15, "default press direction");
}

TEST(Trajectory, UnitsConvertToMetres) {
  const std::string body = "start: [0, 0, 20]\nsegments:\n  - {move_by: [0, 30, 40], speed: 10}\n";
  const Trajectory mm = parse_trajectory("units: mm\n" + body, "mm.yaml");
  const Trajectory cm = parse_trajectory("units: cm\n" + body, "cm.yaml");
  const Trajectory m = parse_trajectory(body, "m.yaml");  // default: m
  for (const Trajectory* tr : {&mm, &cm, &m})
    EXPECT_NEAR(tr->duration(), 5.0, 1e-12);  // 50 units at 10 units/s
  expect_near(mm.position(5.0), Eigen::Vector3d(0, 0.030, 0.060), 1e-15, "mm");
  expect_near(cm.position(5.0), Eigen::Vector3d(0, 0.30, 0.60), 1e-15, "cm");
  expect_near(m.position(5.0), Eigen::Vector3d(0, 30, 60), 1e-12, "m");
  expect_near(mm.velocity(1.0), Eigen::Vector3d(0, 0.006, 0.008), 1e-15, "mm velocity");
}

TEST(Trajectory, MoveToWhereTheToolIsTakesNoTime) {
  const Trajectory tr = parse_trajectory(
      "start: [1, 0, 0]\nsegments:\n  - {move_to: [1, 0, 0], speed: 1}\n  - {hold: 2}\n",
      "still.yaml");
  EXPECT_EQ(tr.knot_times().size(), 2u);
  EXPECT_NEAR(tr.duration(), 2.0, 1e-15);
}

TEST(Trajectory, ButtonsAreHeldForTheirSegmentAndFromTheEndOn) {
  // Approach 10 mm at 10 mm/s (0-1 s, no buttons), hold 2 s with button 0 (1-3 s), a
  // zero-length move with button 1 (takes no time: never seen), pull 20 mm at 10 mm/s with
  // buttons 0 and 2 (3-5 s), hold 1 s with none (5-6 s); then again with repeat, and the
  // last segment's buttons (none) from the end on.
  const Trajectory tr = parse_trajectory(
      "units: mm\nstart: [0, 0, 10]\nsegments:\n  - {move_to: [0, 0, 0], speed: 10}\n  - {hold: 2, "
      "buttons: 1}\n"
      "  - {move_to: [0, 0, 0], speed: 10, buttons: 2}\n  - {move_by: [0, 0, 20], speed: 10, "
      "buttons: 5}\n  - {hold: 1}\n",
      "grasp.yaml");
  ASSERT_NEAR(tr.duration(), 6.0, 1e-12);
  const std::vector<std::pair<double, std::uint32_t>> expected{
      {-1, 0},  {0, 0},   {0.99, 0}, {1.0, 1}, {2.99, 1},
      {3.0, 5}, {4.5, 5}, {5.0, 0},  {5.5, 0}, {9, 0}};
  for (const auto& [t, buttons] : expected) EXPECT_EQ(tr.buttons(t), buttons) << "t = " << t;
  EXPECT_NEAR(tr.position(4.0).z(), 0.010, 1e-15);  // buttons do not move the tool

  const Trajectory holding =
      parse_trajectory("start: [0, 0, 0]\nsegments:\n  - {hold: 1, buttons: 1}\n", "hold.yaml");
  EXPECT_EQ(holding.buttons(0.5), 1u);
  EXPECT_EQ(holding.buttons(7.0), 1u) << "a script that ends holding a button keeps holding it";
  EXPECT_EQ(
      parse_trajectory("start: [0, 0, 0]\nsegments:\n  - {hold: 1}\n", "none.yaml").buttons(0.5),
      0u);

  ScriptedDevice device(tr, 3.3);
  EXPECT_EQ(device.read(1.5).buttons, 1u);
  EXPECT_EQ(device.read(4.0).buttons, 5u);
}

TEST(Trajectory, KnotsAreValidated) {
  EXPECT_NO_THROW(Trajectory({0.0}, {Eigen::Vector3d::Zero()}, "point"));
  EXPECT_THROW(Trajectory({}, {}, "empty"), Error);
  EXPECT_THROW(Trajectory({0.5}, {Eigen::Vector3d::Zero()}, "late start"), Error);
  EXPECT_THROW(Trajectory({0.0, 1.0, 1.0}, std::vector<Eigen::Vector3d>(3, Eigen::Vector3d::Zero()),
                          "repeated time"),
               Error);
  EXPECT_THROW(Trajectory({0.0, 1.0}, {Eigen::Vector3d::Zero()}, "mismatch"), Error);
  EXPECT_THROW(Trajectory({0.0, 1.0}, std::vector<Eigen::Vector3d>(2, Eigen::Vector3d::Zero()),
                          "buttons", {1u}),
               Error);
}

TEST(Trajectory, DemoFilesMatchHandComputation) {
  // press.yaml (mm): 18 mm approach at 20 -> 0.9 s; press 15 at 5 -> 3.9; hold -> 4.9;
  // release -> 7.9; repetitions 2 and 3 skip the (zero-length) approach: +7 s each -> 21.9.
  const Trajectory press = load_trajectory(kDataDir + "press.yaml");
  EXPECT_NEAR(press.duration(), 21.9, 1e-12);
  expect_near(press.position(0.0), Eigen::Vector3d(20, -20, 90) * kMm, 1e-15, "press start");
  expect_near(press.position(4.4), Eigen::Vector3d(20, -20, 57) * kMm, 1e-15,
              "press bottom, stroke 1");
  expect_near(press.position(9.4), Eigen::Vector3d(20, -20, 64.5) * kMm, 1e-15,
              "half way down, stroke 2");
  expect_near(press.position(21.9), Eigen::Vector3d(20, -20, 72) * kMm, 1e-15,
              "released after stroke 3");
  // lift.yaml (mm): approach 20 mm at 20 -> 1.0; press 10 up at 4 -> 3.5; slide +5 y at 2.5
  // -> 5.5; hold 1.5 -> 7.0; slide back -> 9.0; release -> 11.5; repetition 2 -> 22.0.
  const Trajectory lift = load_trajectory(kDataDir + "lift.yaml");
  EXPECT_NEAR(lift.duration(), 22.0, 1e-12);
  expect_near(lift.position(6.0), Eigen::Vector3d(25, -50, -69) * kMm, 1e-15, "lifted and slid");
  expect_near(lift.velocity(4.5), Eigen::Vector3d(0, 2.5, 0) * kMm, 1e-15, "sliding");
  expect_near(lift.position(12.75), Eigen::Vector3d(25, -55, -74) * kMm, 1e-15,
              "half way up, stroke 2");
  const auto hand = load_hand_parameters(kDataDir + "lift.yaml");
  ASSERT_TRUE(hand.has_value());
  EXPECT_EQ(hand->mass_kg, 0.25);
  EXPECT_EQ(hand->stiffness_n_per_m, 400.0);
  EXPECT_EQ(hand->damping_ns_per_m, 10.0);
  EXPECT_FALSE(load_hand_parameters(kDataDir + "press.yaml").has_value());
}

TEST(Trajectory, PositionAndVelocityAllocateNothing) {
  const Trajectory tr = parse_trajectory(kExample, "example.yaml");
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const long calls = count_allocations([&] {
    for (int i = 0; i < 30000; ++i) sum += tr.position(i * 1e-3) + tr.velocity(i * 1e-3);
  });
  if (calls < 0) GTEST_SKIP() << "operator new is not counted in this program";
  EXPECT_EQ(calls, 0);
  EXPECT_TRUE(sum.allFinite());
}

// A valid file in block style, one value per line. Each error case replaces one line and
// expects the message to name that line (counted here, 1-based) and the key path.
const std::string kBlock = R"(units: mm
start: [0, 0, 20]
segments:
  - move_to: [0, 0, 2]
    speed: 20
  - press: 15
    speed: 5
    direction: [0, 0, -1]
  - hold: 1.0
  - release: 15
    speed: 5
repeat: 3
)";

std::string replace_line(const std::string& text, int line, const std::string& with) {
  std::vector<std::string> lines;
  std::size_t begin = 0;
  while (begin < text.size()) {
    const std::size_t end = text.find('\n', begin);
    lines.push_back(text.substr(begin, end - begin));
    begin = end + 1;
  }
  lines.at(static_cast<std::size_t>(line - 1)) = with;
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

TEST(Trajectory, BlockFileIsValid) { EXPECT_NO_THROW(parse_trajectory(kBlock, "block.yaml")); }

struct ErrorCase {
  const char* what;
  int line;             // the line replaced (and expected in the message)
  const char* with;     // its replacement
  const char* key;      // expected key path in the message
  const char* expects;  // expected words in the message
};

TEST(Trajectory, ErrorsNameFileLineAndKey) {
  const std::vector<ErrorCase> cases{
      {"units", 1, "units: inch", "units", "one of m, cm, mm"},
      {"start size", 2, "start: [0, 20]", "start", "a list of 3 numbers"},
      {"start not a number", 2, "start: [0, zero, 20]", "start[1]", "a number"},
      {"zero speed", 5, "    speed: 0", "segments[0].speed", "positive speed"},
      {"negative speed", 7, "    speed: -5", "segments[1].speed", "positive speed"},
      {"infinite speed", 7, "    speed: .inf", "segments[1].speed", "finite number"},
      {"zero direction", 8, "    direction: [0, 0, 0]", "segments[1].direction",
       "non-zero direction"},
      {"zero depth", 6, "  - press: 0", "segments[1].press", "positive depth"},
      {"negative hold", 9, "  - hold: -1", "segments[2].hold", "positive duration"},
      {"zero hold", 9, "  - hold: 0", "segments[2].hold", "positive duration"},
      {"release distance", 10, "  - release: abc", "segments[3].release", "a number"},
      {"repeat zero", 12, "repeat: 0", "repeat", "an integer from 1"},
      {"repeat fraction", 12, "repeat: 1.5", "repeat", "an integer"},
      {"unknown top key", 12, "repaet: 3", "repaet", "unknown key"},
      {"unknown segment key", 8, "    dirction: [0, 0, -1]", "segments[1].dirction", "unknown key"},
      {"segment with no kind", 9, "  - wait: 1.0", "segments[2]",
       "one of move_to, move_by, press, release or hold"},
      {"two kinds", 8, "    hold: 1", "segments[1].hold", "exactly one of"},
      {"missing speed", 5, "    spede: 20", "segments[0].spede", "unknown key"},
      {"negative buttons", 11, "    buttons: -1", "segments[3].buttons", "a button mask"},
  };
  for (const auto& c : cases) {
    const std::string text = replace_line(kBlock, c.line, c.with);
    try {
      parse_trajectory(text, "cases/bad.yaml");
      ADD_FAILURE() << c.what << ": no error for\n" << text;
    } catch (const ParseError& e) {
      const std::string message = e.what();
      EXPECT_EQ(e.file(), "cases/bad.yaml") << c.what;
      EXPECT_EQ(e.line(), c.line) << c.what << ": " << message;
      EXPECT_NE(message.find(std::string("cases/bad.yaml:") + std::to_string(c.line) + ":"),
                std::string::npos)
          << c.what << ": " << message;
      EXPECT_NE(message.find(std::string(" ") + c.key + ":"), std::string::npos)
          << c.what << ": " << message;
      EXPECT_NE(message.find(c.expects), std::string::npos) << c.what << ": " << message;
    }
  }
}

TEST(Trajectory, StructuralErrorsNameFileLineAndKey) {
  struct Case {
    const char* what;
    std::string text;
    int line;
    const char* expects;
  };
  const std::vector<Case> cases{
      {"no segments", "start: [0, 0, 0]\nsegments: []\n", 2,
       "segments: expected at least one segment"},
      {"segments not a list", "start: [0, 0, 0]\nsegments: 3\n", 2,
       "segments: expected a list, found '3'"},
      {"missing start", "units: mm\nsegments:\n  - {hold: 1}\n", 1,
       "(top level): missing required key 'start'"},
      {"missing speed", "start: [0, 0, 0]\nsegments:\n  - {hold: 1}\n  - {move_by: [1, 0, 0]}\n", 4,
       "segments[1]: missing required key 'speed'"},
      {"release before press",
       "start: [0, 0, 0]\nsegments:\n  - {hold: 1}\n  - {release: 1, speed: 1}\n", 4,
       "segments[1]: release before any press"},
      {"not a map", "- 1\n- 2\n", 1, "expected a map with start and segments"},
      {"YAML syntax", "start: [0, 0, 0]\nsegments:\n  - {hold: 1\n", 4, "YAML syntax error"},
  };
  for (const auto& c : cases) {
    try {
      parse_trajectory(c.text, "s.yaml");
      ADD_FAILURE() << c.what << ": no error";
    } catch (const ParseError& e) {
      EXPECT_EQ(e.line(), c.line) << c.what << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(c.expects), std::string::npos)
          << c.what << ": " << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("s.yaml:", 0), 0u) << c.what << ": " << e.what();
    }
  }
  try {
    load_trajectory(kDataDir + "no-such-file.yaml");
    ADD_FAILURE() << "no error for a missing file";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-file.yaml"), std::string::npos) << e.what();
  }
}

TEST(Trajectory, HandMapErrorsNameFileLineAndKey) {
  const std::string base =
      "start: [0, 0, 0]\nsegments: [{hold: 1}]\nhand:\n  mass: 0.2\n  stiffness: 300\n  damping: "
      "8\n";
  EXPECT_NO_THROW(parse_trajectory(base, "h.yaml"));
  const auto ok = parse_hand_parameters(base, "h.yaml");
  ASSERT_TRUE(ok.has_value());
  EXPECT_EQ(ok->mass_kg, 0.2);
  const std::vector<ErrorCase> cases{
      {"mass", 4, "  mass: 0", "hand.mass", "positive mass"},
      {"stiffness", 5, "  stiffness: -3", "hand.stiffness", "positive stiffness"},
      {"damping", 6, "  damping: -1", "hand.damping", "damping >= 0"},
      {"unknown", 6, "  dampnig: 8", "hand.dampnig", "unknown key"},
  };
  for (const auto& c : cases) {
    try {
      parse_hand_parameters(replace_line(base, c.line, c.with), "h.yaml");
      ADD_FAILURE() << c.what << ": no error";
    } catch (const ParseError& e) {
      EXPECT_EQ(e.line(), c.line) << c.what << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(std::string(" ") + c.key + ":"), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find(c.expects), std::string::npos) << e.what();
    }
  }
  // Defaults for keys left out; damping 0 is allowed (an undamped arm).
  const auto partial = parse_hand_parameters("hand: {damping: 0}\n", "p.yaml");
  ASSERT_TRUE(partial.has_value());
  EXPECT_EQ(partial->mass_kg, HandParameters{}.mass_kg);
  EXPECT_EQ(partial->damping_ns_per_m, 0.0);
}

// ---------------------------------------------------------------------------------------
// Scripted device and make_device

TEST(Device, ScriptedPlaysTheTrajectoryAndKeepsTheForce) {
  ScriptedDevice device(load_trajectory(kDataDir + "press.yaml"), 3.3);
  EXPECT_EQ(device.force_limit(), 3.3);
  const DeviceState s = device.read(2.4);  // 1.5 s into the first press: 7.5 mm below 72
  EXPECT_TRUE(s.valid);
  EXPECT_EQ(s.buttons, 0u);
  expect_near(s.position, Eigen::Vector3d(20, -20, 64.5) * kMm, 1e-15, "scripted position");
  device.write_force(Eigen::Vector3d(0, 0, 1.25), 2.4);
  EXPECT_EQ(device.last_force(), Eigen::Vector3d(0, 0, 1.25));
  EXPECT_EQ(device.last_force_time(), 2.4);
  // The force does not change the script.
  expect_near(device.read(2.4).position, s.position, 0.0, "open loop");
  EXPECT_FALSE(device.finished(21.9));
  EXPECT_TRUE(device.finished(21.9 + 1e-9));
  EXPECT_NE(device.describe().find("script:"), std::string::npos);
  EXPECT_THROW(ScriptedDevice(load_trajectory(kDataDir + "press.yaml"), 0.0), Error);

  const long calls = count_allocations([&] {
    for (int i = 0; i < 10000; ++i) {
      const DeviceState st = device.read(i * 1e-3);
      device.write_force(st.position, i * 1e-3);
    }
  });
  if (calls >= 0) {
    EXPECT_EQ(calls, 0) << "ScriptedDevice allocated in read/write_force";
  }
}

TEST(Device, MakeDeviceFromSpecs) {
  const auto script = make_device("script:" + kDataDir + "press.yaml", 3.0);
  ASSERT_NE(dynamic_cast<ScriptedDevice*>(script.get()), nullptr);
  EXPECT_EQ(script->force_limit(), 3.0);

  const auto hand = make_device("hand:" + kDataDir + "lift.yaml", 2.0);
  const auto* hand_model = dynamic_cast<HandModelDevice*>(hand.get());
  ASSERT_NE(hand_model, nullptr);
  EXPECT_EQ(hand_model->parameters().stiffness_n_per_m, 400.0);  // from the file's hand: map
  const auto hand_defaults = make_device("hand:" + kDataDir + "press.yaml", 2.0);
  ASSERT_NE(dynamic_cast<HandModelDevice*>(hand_defaults.get()), nullptr);
  EXPECT_EQ(dynamic_cast<HandModelDevice*>(hand_defaults.get())->parameters().stiffness_n_per_m,
            300.0);

  const auto bridge = make_device("bridge:17493", 3.3);
  ASSERT_NE(dynamic_cast<BridgeDevice*>(bridge.get()), nullptr);
  EXPECT_NE(bridge->describe().find("bridge:127.0.0.1:17493"), std::string::npos)
      << bridge->describe();
  const auto bridge_host = make_device("bridge:0.0.0.0:17494", 3.3);
  EXPECT_NE(bridge_host->describe().find("bridge:0.0.0.0:17494"), std::string::npos)
      << bridge_host->describe();

  for (const char* bad : {"", "script", "script:", "mouse:1", "bridge:", "bridge:abc",
                          "bridge:70000", "bridge:0", "bridge:host:", "Script:x.yaml"}) {
    try {
      make_device(bad, 3.0);
      ADD_FAILURE() << "no error for '" << bad << "'";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(std::string("'") + bad + "'"), std::string::npos) << message;
      if (message.find("unknown device") != std::string::npos) {
        for (const char* form :
             {"script:FILE", "hand:FILE", "bridge:[HOST:]PORT", "replay:FILE[:USER]"})
          EXPECT_NE(message.find(form), std::string::npos) << "'" << bad << "': " << message;
      }
    }
  }
  EXPECT_THROW(make_device("script:" + kDataDir + "no-such-file.yaml", 3.0), ParseError);
  EXPECT_EQ(device_spec_forms().size(), 4u);
}

// ---------------------------------------------------------------------------------------
// Hand model. Defaults m = 0.2, k = 300, c = 8: sigma = c / 2m = 20 /s,
// omega0^2 = k / m = 1500, omega_d = sqrt(1500 - 400) = sqrt(1100) rad/s.

constexpr double kSigma = 20.0;
const double kOmega0 = std::sqrt(1500.0);
const double kOmegaD = std::sqrt(1100.0);

Trajectory still_at(const Eigen::Vector3d& p) { return Trajectory({0.0}, {p}, "still"); }

// Runs a device at 1 kHz for `seconds`, with force(state) fed back; calls `each(t, state)`.
void run_loop(HapticDevice& device, double seconds,
              const std::function<Eigen::Vector3d(const DeviceState&)>& force,
              const std::function<void(double, const DeviceState&)>& each) {
  const int ticks = static_cast<int>(std::lround(seconds * 1000.0));
  for (int i = 0; i <= ticks; ++i) {
    const double t = i * 1e-3;
    const DeviceState s = device.read(t);
    each(t, s);
    device.write_force(force(s), t);
  }
}

// Step: the reference is still at r = 0 and the arm starts at rest 10 mm away, which is
// the step response of m x'' + c x' + k x = k r with e = x - r:
//   e(t) = e0 exp(-sigma t) (cos(omega_d t) + sigma / omega_d sin(omega_d t)).
// Semi-implicit Euler is first order: the global error is bounded by C h with C of order
// e0 omega0 (the phase error per unit time is ~ omega0^2 h / 2, times an envelope
// omega0 t exp(-sigma t) <= omega0 / (e sigma)). We assert the max error over 1.5 s is
// below e0 omega0 h (= 3.9e-5 m at h = 0.1 ms), and that halving h halves it (order 1).
double step_error(double h, double e0) {
  HandModelDevice hand(still_at(Eigen::Vector3d::Zero()), HandParameters{}, 3.0, h);
  hand.set_state({0.0, Eigen::Vector3d(0, 0, e0), Eigen::Vector3d::Zero()});
  double worst = 0;
  run_loop(
      hand, 1.5, [](const DeviceState&) { return Eigen::Vector3d::Zero(); },
      [&](double t, const DeviceState& s) {
        const double exact = e0 * std::exp(-kSigma * t) *
                             (std::cos(kOmegaD * t) + kSigma / kOmegaD * std::sin(kOmegaD * t));
        worst = std::max(worst, std::abs(s.position.z() - exact));
        EXPECT_EQ(s.position.x(), 0.0);
      });
  return worst;
}

TEST(HandModel, StepResponseMatchesTheDampedOscillator) {
  const double e0 = 0.010;
  const double h = HandModelDevice::kDefaultMaxSubstep;
  const double error = step_error(h, e0);
  const double error_half = step_error(h / 2, e0);
  const double bound = e0 * kOmega0 * h;
  RecordProperty("step_max_error_m", std::to_string(error));
  RecordProperty("step_bound_m", std::to_string(bound));
  std::printf(
      "hand model step, e0 = 10 mm: max error %.3g m at h = 0.1 ms, %.3g m at 0.05 ms (bound %.3g "
      "m)\n",
      error, error_half, bound);
  EXPECT_LT(error, bound);
  EXPECT_NEAR(error / error_half, 2.0, 0.2) << "semi-implicit Euler should be first order";
}

// Ramp: the reference moves at u = 50 mm/s along x for 1 s from where the arm rests. With
// the damper on r' - x', e = x - r obeys the same homogeneous equation with e(0) = 0,
// e'(0) = -u:  e(t) = -(u / omega_d) exp(-sigma t) sin(omega_d t), no steady lag.
TEST(HandModel, RampResponseMatchesTheDampedOscillator) {
  const double u = 0.05;
  Trajectory ramp({0.0, 1.0}, {Eigen::Vector3d::Zero(), Eigen::Vector3d(u, 0, 0)}, "ramp");
  HandModelDevice hand(ramp, HandParameters{}, 3.0);
  double worst = 0;
  const double h = HandModelDevice::kDefaultMaxSubstep;
  run_loop(
      hand, 0.999, [](const DeviceState&) { return Eigen::Vector3d::Zero(); },
      [&](double t, const DeviceState& s) {
        const double exact = u * t - u / kOmegaD * std::exp(-kSigma * t) * std::sin(kOmegaD * t);
        worst = std::max(worst, std::abs(s.position.x() - exact));
      });
  // The amplitude of e is u / omega_d = 1.5 mm; same bound as for the step, with that amplitude.
  const double bound = u / kOmegaD * kOmega0 * h;
  std::printf("hand model ramp, 50 mm/s: max error %.3g m (bound %.3g m)\n", worst, bound);
  EXPECT_LT(worst, bound);
  // After the reference stops, the arm comes to rest on it.
  for (int i = 1000; i <= 4000; ++i) hand.read(i * 1e-3);
  expect_near(hand.state().position, Eigen::Vector3d(u, 0, 0), 1e-9,
              "at rest on the end of the ramp");
}

TEST(HandModel, ConstantForceSettlesAtReferencePlusForceOverStiffness) {
  const Eigen::Vector3d r(0.01, -0.02, 0.03);
  const Eigen::Vector3d force(0.5, -1.0, 1.5);
  HandModelDevice hand(still_at(r), HandParameters{}, 3.0);
  run_loop(
      hand, 3.0, [&](const DeviceState&) { return force; }, [](double, const DeviceState&) {});
  // The envelope decays as exp(-20 t): after 3 s, 1e-26 of the 5 mm offset; the discrete
  // fixed point (v = 0, k (r - x) + F = 0) is exact.
  expect_near(hand.state().position, r + force / 300.0, 1e-12, "settled");
  EXPECT_LT(hand.state().velocity.norm(), 1e-12);
  // Non-finite forces are counted and treated as zero.
  hand.write_force(Eigen::Vector3d(std::nan(""), 0, 0), 3.0);
  EXPECT_EQ(hand.non_finite_forces(), 1u);
  EXPECT_EQ(hand.applied_force(), Eigen::Vector3d::Zero());
}

// c = 0, still reference, no force: E = m v^2 / 2 + k (x - r)^2 / 2 should stay constant.
// Semi-implicit Euler (v first, then x with the new v) conserves the nearby quadratic
//   E~ = m v^2 / 2 + k x^2 / 2 - h k x v / 2
// exactly (check: it is invariant under v' = v - h k x / m, x' = x + h v'), so E itself
// only oscillates, with a relative amplitude of at most omega0 h / 2 (0.19 % at 0.1 ms),
// and never drifts. We assert |E/E0 - 1| < omega0 h and E~ constant to 1e-10 over 100 s.
TEST(HandModel, UndampedEnergyStaysWithinTheSymplecticBound) {
  const HandParameters p{0.2, 300.0, 0.0};
  HandModelDevice hand(still_at(Eigen::Vector3d::Zero()), p, 3.0);
  const double x0 = 0.01;
  hand.set_state({0.0, Eigen::Vector3d(x0, 0, 0), Eigen::Vector3d::Zero()});
  const double h = hand.max_substep();
  const double k = p.stiffness_n_per_m, m = p.mass_kg;
  const auto energy = [&](const HandState& st) {
    return 0.5 * m * st.velocity.squaredNorm() + 0.5 * k * st.position.squaredNorm();
  };
  const auto modified = [&](const HandState& st) {
    return energy(st) - 0.5 * h * k * st.position.dot(st.velocity);
  };
  const double e0 = energy(hand.state());
  const double q0 = modified(hand.state());
  double worst = 0, worst_modified = 0;
  const double seconds = 100.0;
  run_loop(
      hand, seconds, [](const DeviceState&) { return Eigen::Vector3d::Zero(); },
      [&](double, const DeviceState&) {
        worst = std::max(worst, std::abs(energy(hand.state()) / e0 - 1.0));
        worst_modified = std::max(worst_modified, std::abs(modified(hand.state()) / q0 - 1.0));
      });
  std::printf(
      "hand model, c = 0 for 100 s (%.0f periods): max |E/E0 - 1| = %.3g (bound omega0 h = %.3g); "
      "max |E~/E~0 - 1| = %.3g\n",
      seconds * kOmega0 / (2 * std::numbers::pi), worst, kOmega0 * h, worst_modified);
  EXPECT_LT(worst, kOmega0 * h);
  EXPECT_GT(worst, 0.25 * kOmega0 * h)
      << "E should oscillate by about omega0 h / 2 (is the integrator symplectic Euler?)";
  EXPECT_LT(worst_modified, 1e-10);
  EXPECT_EQ(hand.substep_count(), static_cast<std::uint64_t>(std::lround(seconds / h)));
}

TEST(HandModel, SubstepsAtMostATenthOfAMillisecond) {
  HandModelDevice hand(still_at(Eigen::Vector3d::Zero()), HandParameters{}, 3.0);
  hand.read(1e-3);
  EXPECT_EQ(hand.substep_count(), 10u);
  hand.read(1e-3 + 3.3e-3);  // a late tick: 33 sub-steps
  EXPECT_EQ(hand.substep_count(), 43u);
  hand.read(1e-3);  // time going backwards is ignored
  EXPECT_EQ(hand.substep_count(), 43u);
  hand.read(10.0);  // a stall longer than 0.5 s: the rest is skipped, and counted
  EXPECT_EQ(hand.substep_count(),
            43u + static_cast<std::uint64_t>(HandModelDevice::kMaxSubstepsPerRead));
  EXPECT_NEAR(hand.skipped_time_s(), 10.0 - 4.3e-3 - 0.5, 1e-9);
  EXPECT_EQ(hand.state().time_s, 10.0);
  // Parameters the sub-step cannot resolve are refused.
  EXPECT_THROW(
      HandModelDevice(still_at(Eigen::Vector3d::Zero()), HandParameters{0.001, 1e5, 0}, 3.0),
      Error);
  EXPECT_THROW(
      HandModelDevice(still_at(Eigen::Vector3d::Zero()), HandParameters{0.01, 300, 100}, 3.0),
      Error);
  EXPECT_THROW(
      HandModelDevice(still_at(Eigen::Vector3d::Zero()), HandParameters{0.2, 300, 8}, 3.0, 2e-4),
      Error);
  EXPECT_THROW(HandModelDevice(still_at(Eigen::Vector3d::Zero()), HandParameters{-1, 300, 8}, 3.0),
               Error);
}

// Closed loop against a unilateral virtual wall z >= 0 of stiffness K, rendered at 1 kHz
// with the force held between ticks: F = K max(-z, 0) along +z. The reference presses to
// r = -13 mm. Equilibrium (from m x'' = k (r - x) + K (-x)): x = k r / (k + K).
// Colgate & Schenkel (1997): such a sampled wall is passive if the damping b of what
// touches it exceeds K T / 2. With the hand's c = 8 N s/m and T = 1 ms: K = 5000 N/m
// (K T / 2 = 2.5) settles on the equilibrium; K = 1e5 N/m (K T / 2 = 50) chatters.
struct WallRun {
  double final_z;
  double late_peak_to_peak;  // over the last 0.5 s of 3 s
};
WallRun run_wall(double wall_k) {
  const Eigen::Vector3d r(0, 0, -0.013);
  HandModelDevice hand(still_at(r), HandParameters{}, 1e9);
  hand.set_state({0.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
  double lo = INFINITY, hi = -INFINITY;
  run_loop(
      hand, 3.0,
      [&](const DeviceState& s) {
        return Eigen::Vector3d(0, 0, wall_k * std::max(-s.position.z(), 0.0));
      },
      [&](double t, const DeviceState& s) {
        if (t >= 2.5) {
          lo = std::min(lo, s.position.z());
          hi = std::max(hi, s.position.z());
        }
      });
  return {hand.state().position.z(), hi - lo};
}

TEST(HandModel, SettlesAgainstAVirtualWallWhenPassive) {
  const double k = 300, wall = 5000;
  const WallRun run = run_wall(wall);
  EXPECT_NEAR(run.final_z, k * -0.013 / (k + wall), 1e-9);
  EXPECT_LT(run.late_peak_to_peak, 1e-9);
}

TEST(HandModel, ChattersAgainstAStiffWallBeyondThePassivityBound) {
  const WallRun run = run_wall(1e5);
  std::printf(
      "hand model against a 1e5 N/m wall at 1 kHz: peak-to-peak %.3g m over the last 0.5 s\n",
      run.late_peak_to_peak);
  EXPECT_GT(run.late_peak_to_peak, 1e-4)
      << "the closed loop should show the sampled-wall instability";
}

TEST(HandModel, ReadAndWriteAllocateNothing) {
  HandModelDevice hand(load_trajectory(kDataDir + "press.yaml"), HandParameters{}, 3.0);
  const long calls = count_allocations([&] {
    run_loop(
        hand, 5.0,
        [](const DeviceState& s) {
          return Eigen::Vector3d(0, 0, 100.0 * std::max(0.07 - s.position.z(), 0.0));
        },
        [](double, const DeviceState&) {});
  });
  if (calls < 0) GTEST_SKIP() << "operator new is not counted in this program";
  EXPECT_EQ(calls, 0);
}

// ---------------------------------------------------------------------------------------
// Bridge

/// Waits until `device` has read `datagrams` datagrams in total, reading at loop time t.
::testing::AssertionResult read_until(BridgeDevice& device, std::uint64_t datagrams, double t) {
  return testing::wait_until(
      [&] {
        device.read(t);
        return device.counters().received >= datagrams;
      },
      std::to_string(datagrams) + " datagrams read by the bridge device");
}

/// Waits until a force packet from the device has reached `peer`.
::testing::AssertionResult force_arrives(BridgePeer& peer) {
  return testing::wait_until(
      [&] { return peer.poll_forces() > 0 || peer.newest_force().has_value(); },
      "a force packet at the bridge peer");
}

TEST(Bridge, PacketLayoutIsLittleEndianAndFixed) {
  bridge::PosePacket pose;
  pose.sequence = 0x01020304u;
  pose.device_time_s = 2.0;          // 0x4000000000000000
  pose.position = {1.0, -2.0, 0.5};  // 0x3FF0..., 0xC000..., 0x3FE0...
  pose.buttons = 5;
  pose.flags = bridge::kPoseValid;
  bridge::PoseBytes bytes;
  bridge::encode(pose, bytes);
  const std::vector<std::uint8_t> expected{
      'C', 'H', 'B', '1', 0x04, 0x03, 0x02, 0x01,  // magic, sequence
      0,   0,   0,   0,   0,    0,    0x00, 0x40,  // device_time_s = 2
      0,   0,   0,   0,   0,    0,    0xF0, 0x3F,  // x = 1
      0,   0,   0,   0,   0,    0,    0x00, 0xC0,  // y = -2
      0,   0,   0,   0,   0,    0,    0xE0, 0x3F,  // z = 0.5
      5,   0,   0,   0,   1,    0,    0,    0};    // buttons, flags
  ASSERT_EQ(bytes.size(), 48u);
  EXPECT_TRUE(std::equal(bytes.begin(), bytes.end(), expected.begin()));
  bridge::PosePacket back;
  ASSERT_EQ(bridge::decode(bytes, back), bridge::PacketStatus::ok);
  EXPECT_EQ(back.sequence, pose.sequence);
  EXPECT_EQ(back.position, pose.position);
  EXPECT_EQ(back.buttons, 5u);

  bridge::ForcePacket force;
  force.sequence = 7;
  force.device_time_s = -2.0;
  force.force = {0.5, 1.0, -2.0};
  force.force_limit = 2.0;
  force.flags = bridge::kClientValid;
  bridge::ForceBytes fbytes;
  bridge::encode(force, fbytes);
  const std::vector<std::uint8_t> fexpected{
      'C', 'H', 'F', '1', 7, 0, 0,    0,     //
      0,   0,   0,   0,   0, 0, 0x00, 0xC0,  // device_time_s = -2
      0,   0,   0,   0,   0, 0, 0xE0, 0x3F,  // fx = 0.5
      0,   0,   0,   0,   0, 0, 0xF0, 0x3F,  // fy = 1
      0,   0,   0,   0,   0, 0, 0x00, 0xC0,  // fz = -2
      0,   0,   0,   0,   0, 0, 0x00, 0x40,  // force_limit = 2
      1,   0,   0,   0,   0, 0, 0,    0};    // flags, reserved
  ASSERT_EQ(fbytes.size(), 56u);
  EXPECT_TRUE(std::equal(fbytes.begin(), fbytes.end(), fexpected.begin()));

  // Rejections.
  EXPECT_EQ(bridge::decode(std::span<const std::uint8_t>(bytes.data(), 47), back),
            bridge::PacketStatus::bad_size);
  bridge::PoseBytes wrong = bytes;
  wrong[3] = '2';
  EXPECT_EQ(bridge::decode(wrong, back), bridge::PacketStatus::bad_magic);
  pose.position.y() = std::numeric_limits<double>::infinity();
  bridge::encode(pose, wrong);
  EXPECT_EQ(bridge::decode(wrong, back), bridge::PacketStatus::non_finite);
  EXPECT_EQ(bridge::decode(fbytes, back),
            bridge::PacketStatus::bad_size);  // a force packet is not a pose
  // Sequence order wraps.
  EXPECT_TRUE(bridge::sequence_after(1, 0));
  EXPECT_TRUE(bridge::sequence_after(0, 0xFFFFFFFFu));
  EXPECT_FALSE(bridge::sequence_after(5, 5));
  EXPECT_FALSE(bridge::sequence_after(4, 5));
}

TEST(Bridge, PoseAndForceRoundTripOnLoopback) {
  BridgeDevice device({"127.0.0.1", 0, 0.05, 256}, 3.3);
  EXPECT_FALSE(device.read(0.0).valid) << "no socket yet";
  device.start();
  ASSERT_NE(device.local_port(), 0);
  EXPECT_FALSE(device.read(0.0).valid) << "no pose yet";
  device.write_force(Eigen::Vector3d(1, 2, 3), 0.0);
  EXPECT_EQ(device.counters().forces_sent, 0u) << "nothing to send to before the program is heard";

  BridgePeer peer("127.0.0.1", device.local_port());
  ASSERT_TRUE(peer.send_pose(Eigen::Vector3d(0.01, -0.02, 0.03), 12.5, 0b101));
  ASSERT_TRUE(read_until(device, 1, 1.0));
  const DeviceState s = device.read(1.0);
  EXPECT_TRUE(s.valid);
  EXPECT_EQ(s.position, Eigen::Vector3d(0.01, -0.02, 0.03));
  EXPECT_EQ(s.buttons, 0b101u);
  EXPECT_TRUE(device.has_peer());
  EXPECT_EQ(device.peer(), "127.0.0.1:" + std::to_string(peer.local_port()));

  device.write_force(Eigen::Vector3d(0.25, -0.5, 1.75), 1.0);
  ASSERT_TRUE(force_arrives(peer));
  const auto& f = *peer.newest_force();
  EXPECT_EQ(f.sequence, 0u);
  EXPECT_EQ(f.device_time_s, 12.5);
  EXPECT_EQ(f.force, Eigen::Vector3d(0.25, -0.5, 1.75));
  EXPECT_EQ(f.force_limit, 3.3);
  EXPECT_EQ(f.flags, bridge::kClientValid);
  EXPECT_EQ(device.counters().forces_sent, 1u);
  EXPECT_EQ(device.counters().accepted, 1u);
  EXPECT_EQ(device.counters().dropped(), 0u);
  device.stop();
}

TEST(Bridge, NewestPoseWinsAndOlderOnesAreStale) {
  BridgeDevice device({"127.0.0.1", 0, 0.05, 256}, 3.3);
  device.start();
  BridgePeer peer("127.0.0.1", device.local_port());
  for (int i = 0; i < 10; ++i) peer.send_pose(Eigen::Vector3d(i * 1e-3, 0, 0), i * 1e-3);
  ASSERT_TRUE(read_until(device, 10, 1.0));
  EXPECT_EQ(device.read(1.0).position.x(), 9 * 1e-3) << "the newest of the ten";
  EXPECT_EQ(device.newest_pose().sequence, 9u);

  // Out of order: 12, then 11 (older) and a replay of 9.
  bridge::PosePacket p;
  p.sequence = 12;
  p.position = {0.012, 0, 0};
  peer.send_pose(p);
  p.sequence = 11;
  p.position = {0.011, 0, 0};
  peer.send_pose(p);
  p.sequence = 9;
  p.position = {0.009, 0, 0};
  peer.send_pose(p);
  ASSERT_TRUE(read_until(device, 13, 1.001));
  EXPECT_EQ(device.read(1.001).position.x(), 0.012);
  const BridgeCounters c = device.counters();
  EXPECT_EQ(c.stale, 2u);
  EXPECT_EQ(c.received, 13u);
  // All ten of the first burst count as accepted when drained in order (each newer than the last).
  EXPECT_EQ(c.accepted, 11u);
  device.stop();
}

TEST(Bridge, BadPacketsAreDroppedAndCounted) {
  BridgeDevice device({"127.0.0.1", 0, 0.05, 256}, 3.3);
  device.start();
  BridgePeer peer("127.0.0.1", device.local_port());
  BridgePeer intruder("127.0.0.1", device.local_port());

  // Before any good pose, garbage does not make its sender the program.
  const std::vector<std::uint8_t> junk(48, 0x55);
  intruder.send_bytes(junk);  // bad magic
  ASSERT_TRUE(read_until(device, 1, 0.5));
  EXPECT_FALSE(device.has_peer());

  peer.send_pose(Eigen::Vector3d(0.001, 0.002, 0.003), 0.0);
  ASSERT_TRUE(read_until(device, 2, 1.0));
  ASSERT_TRUE(device.has_peer());

  bridge::PoseBytes good;
  bridge::PosePacket p;
  p.sequence = 100;
  p.position = {0.5, 0.5, 0.5};
  bridge::encode(p, good);
  intruder.send_pose(p);                                            // foreign source (well formed)
  peer.send_bytes(std::span<const std::uint8_t>(good.data(), 40));  // short
  std::vector<std::uint8_t> longer(good.begin(), good.end());
  longer.resize(64, 0);
  peer.send_bytes(longer);  // long
  bridge::PoseBytes bad_magic = good;
  bad_magic[0] = 'X';
  peer.send_bytes(bad_magic);  // magic
  p.position.z() = std::numeric_limits<double>::quiet_NaN();
  peer.send_pose(p);  // NaN
  p.position.z() = 0.5;
  p.device_time_s = std::numeric_limits<double>::infinity();
  peer.send_pose(p);  // infinite time
  ASSERT_TRUE(read_until(device, 8, 1.001));

  const BridgeCounters c = device.counters();
  EXPECT_EQ(c.received, 8u);
  EXPECT_EQ(c.accepted, 1u);
  EXPECT_EQ(c.foreign_source, 1u);
  EXPECT_EQ(c.bad_size, 2u);
  EXPECT_EQ(c.bad_magic, 2u);
  EXPECT_EQ(c.non_finite, 2u);
  EXPECT_EQ(c.dropped(), 7u);
  const DeviceState s = device.read(1.002);
  EXPECT_TRUE(s.valid);
  EXPECT_EQ(s.position, Eigen::Vector3d(0.001, 0.002, 0.003))
      << "none of the bad packets got through";
  device.stop();
}

TEST(Bridge, TimeoutMakesThePoseInvalid) {
  BridgeDevice device({"127.0.0.1", 0, 0.05, 256}, 3.3);
  device.start();
  BridgePeer peer("127.0.0.1", device.local_port());
  bridge::PosePacket p;
  p.sequence = 500;
  p.position = {0.01, 0, 0};
  peer.send_pose(p);
  ASSERT_TRUE(read_until(device, 1, 2.0));  // accepted at loop time 2.0
  EXPECT_TRUE(device.read(2.05).valid) << "50 ms: still within the timeout";
  const DeviceState late = device.read(2.0501);
  EXPECT_FALSE(late.valid) << "more than 50 ms without a pose";
  EXPECT_EQ(late.position, Eigen::Vector3d(0.01, 0, 0)) << "the last position is kept";
  EXPECT_EQ(late.buttons, 0u);

  // The force packet says the client had no valid pose.
  device.write_force(Eigen::Vector3d::Zero(), 2.0501);
  ASSERT_TRUE(force_arrives(peer));
  EXPECT_EQ(peer.newest_force()->flags & bridge::kClientValid, 0u);

  // After a timeout, a restarted program (sequence from 0 again) is taken at once.
  p.sequence = 0;
  p.position = {0.02, 0, 0};
  peer.send_pose(p);
  ASSERT_TRUE(read_until(device, 2, 3.0));
  const DeviceState again = device.read(3.0);
  EXPECT_TRUE(again.valid);
  EXPECT_EQ(again.position, Eigen::Vector3d(0.02, 0, 0));

  // A pose flagged "not valid" keeps the last valid position and reports invalid.
  p.sequence = 1;
  p.position = {0.5, 0.5, 0.5};
  p.flags = 0;
  peer.send_pose(p);
  ASSERT_TRUE(read_until(device, 3, 3.01));
  const DeviceState flagged = device.read(3.01);
  EXPECT_FALSE(flagged.valid);
  EXPECT_EQ(flagged.position, Eigen::Vector3d(0.02, 0, 0));
  device.stop();
}

TEST(Bridge, ReadAndWriteAllocateNothing) {
  BridgeDevice device({"127.0.0.1", 0, 0.05, 256}, 3.3);
  device.start();
  BridgePeer peer("127.0.0.1", device.local_port());
  peer.send_pose(Eigen::Vector3d(0.01, 0, 0), 0.0);
  ASSERT_TRUE(read_until(device, 1, 0.0));
  for (int i = 1; i <= 50; ++i) peer.send_pose(Eigen::Vector3d(0.01, 0, i * 1e-4), i * 1e-3);
  const long calls = count_allocations([&] {
    for (int i = 0; i < 200; ++i) {
      const DeviceState s = device.read(i * 1e-4);
      device.write_force(Eigen::Vector3d(0, 0, s.position.z()), i * 1e-4);
    }
  });
  if (calls < 0) GTEST_SKIP() << "operator new is not counted in this program";
  EXPECT_EQ(calls, 0);
  EXPECT_GT(device.counters().forces_sent, 0u);
  device.stop();
}

TEST(Bridge, PortInUseIsAnError) {
  BridgeDevice first({"127.0.0.1", 0, 0.05, 256}, 3.3);
  first.start();
  BridgeDevice second({"127.0.0.1", first.local_port(), 0.05, 256}, 3.3);
  EXPECT_THROW(second.start(), Error);
  BridgeDevice bad_host({"not-an-address", 0, 0.05, 256}, 3.3);
  EXPECT_THROW(bad_host.start(), Error);
  EXPECT_THROW(BridgeDevice({"127.0.0.1", 0, 0.0, 256}, 3.3), Error);
}

}  // namespace
}  // namespace cohaptic
