// The wire layer (proto/wire/): session keys, authentication tags, the datagram codec and
// its replay window and rejection counters (every reason with a hand-made hostile packet,
// and random garbage), the TCP frame reader, and the IR and surface conversions.
#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <string>

#include "common/ir/evaluate_force.h"
#include "common/scene/load_scene.h"
#include "common/sim/simulation.h"
#include "proto/wire/authenticated.h"
#include "proto/wire/datagram_codec.h"
#include "proto/wire/frame_codec.h"
#include "proto/wire/header.h"
#include "proto/wire/ir_convert.h"
#include "proto/wire/replay_window.h"
#include "proto/wire/session_key.h"
#include "support/cube_scene.h"
#include "support/evaluate_static.h"

namespace cohaptic::wire {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr std::uint64_t kSession = 0x5e5510'0001;

SessionKey key_of(std::uint8_t seed) {
  SessionKey key;
  for (std::size_t i = 0; i < key.bytes.size(); ++i) key.bytes[i] = static_cast<std::uint8_t>(seed + 7 * i);
  return key;
}

// ---- session keys ----

class TempDir {
 public:
  TempDir() {
    path_ = std::filesystem::temp_directory_path() / fmt::format("cohaptic-wire-{}-{}", ::getpid(), counter_++);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  static inline int counter_ = 0;
  std::filesystem::path path_;
};

void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const cohaptic::Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(WireSessionKey, LoadsHexWithWhitespaceInEitherCase) {
  TempDir dir;
  write_text(dir / "key.txt", "  00112233445566778899AABBCCDDEEFF\n\t00112233445566778899aabbccddeeff  \r\n");
  const SessionKey key = load_session_key(dir / "key.txt");
  for (std::size_t i = 0; i < 16; ++i) {
    EXPECT_EQ(key.bytes[i], static_cast<std::uint8_t>(0x11 * i));
    EXPECT_EQ(key.bytes[16 + i], static_cast<std::uint8_t>(0x11 * i));
  }
  EXPECT_EQ(to_hex(key), "00112233445566778899aabbccddeeff00112233445566778899aabbccddeeff");
}

TEST(WireSessionKey, RejectsMalformedFilesNamingFileAndProblem) {
  TempDir dir;
  write_text(dir / "short.txt", "0123456789ab\n");
  const std::string short_error = error_of([&] { load_session_key(dir / "short.txt"); });
  EXPECT_NE(short_error.find("short.txt: expected 64 hexadecimal characters, found 12"), std::string::npos) << short_error;

  write_text(dir / "long.txt", std::string(66, 'a'));
  EXPECT_NE(error_of([&] { load_session_key(dir / "long.txt"); }).find("found 66"), std::string::npos);

  write_text(dir / "bad.txt", std::string(40, 'a') + "g" + std::string(23, 'a'));
  const std::string bad_error = error_of([&] { load_session_key(dir / "bad.txt"); });
  EXPECT_NE(bad_error.find("bad.txt"), std::string::npos) << bad_error;
  EXPECT_NE(bad_error.find("'g'"), std::string::npos) << bad_error;
  EXPECT_NE(bad_error.find("column 41"), std::string::npos) << bad_error;

  write_text(dir / "zero.txt", std::string(64, '0'));
  EXPECT_NE(error_of([&] { load_session_key(dir / "zero.txt"); }).find("all zeros"), std::string::npos);

  const std::string missing = error_of([&] { load_session_key(dir / "missing.txt"); });
  EXPECT_NE(missing.find("missing.txt"), std::string::npos) << missing;
}

TEST(WireSessionKey, WritesFreshPrivateRandomKeys) {
  TempDir dir;
  write_session_key(dir / "a.key");
  write_session_key(dir / "b.key");
  struct stat st {};
  ASSERT_EQ(::stat((dir / "a.key").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  const SessionKey a = load_session_key(dir / "a.key");
  const SessionKey b = load_session_key(dir / "b.key");
  EXPECT_NE(a.bytes, b.bytes);
  EXPECT_EQ(std::filesystem::file_size(dir / "a.key"), 65u);  // 64 hex digits and a newline
  // Never overwrites.
  EXPECT_NE(error_of([&] { write_session_key(dir / "a.key"); }).find("a.key"), std::string::npos);
  EXPECT_EQ(load_session_key(dir / "a.key").bytes, a.bytes);
}

TEST(WireSessionKey, DevelopmentKeyIsTheDocumentedText) {
  const std::string text = "cohaptic-development-key-public!";
  const SessionKey key = development_key();
  EXPECT_EQ(std::string(key.bytes.begin(), key.bytes.end()), text);
  EXPECT_EQ(to_hex(key), "636f6861707469632d646576656c6f706d656e742d6b65792d7075626c696321");
}

// ---- authentication ----

TEST(WireAuthenticated, TagIsHmacSha512TruncatedTo256Bits) {
  const SessionKey key = key_of(3);
  const Bytes payload = {1, 2, 3, 4, 5, 250, 0, 17};
  const Bytes packet = seal(payload, key);
  ASSERT_EQ(packet.size(), payload.size() + kTagBytes);
  EXPECT_TRUE(std::equal(payload.begin(), payload.end(), packet.begin()));
  // Independently: the first 32 bytes of HMAC-SHA-512 with the same 32-byte key.
  std::array<std::uint8_t, crypto_auth_hmacsha512_BYTES> full{};
  crypto_auth_hmacsha512_state state;
  crypto_auth_hmacsha512_init(&state, key.bytes.data(), key.bytes.size());
  crypto_auth_hmacsha512_update(&state, payload.data(), payload.size());
  crypto_auth_hmacsha512_final(&state, full.data());
  EXPECT_TRUE(std::equal(full.begin(), full.begin() + kTagBytes, packet.begin() + static_cast<long>(payload.size())));

  const auto opened = open(packet, key);
  ASSERT_TRUE(opened);
  EXPECT_TRUE(std::equal(opened->begin(), opened->end(), payload.begin(), payload.end()));
  EXPECT_FALSE(open(packet, key_of(4)));
  EXPECT_FALSE(open(std::span(packet).first(kTagBytes - 1), key));
  Bytes flipped = packet;
  flipped[2] ^= 0x01;
  EXPECT_FALSE(open(flipped, key));
  // An empty payload has a tag too.
  const Bytes empty_packet = seal({}, key);
  ASSERT_TRUE(open(empty_packet, key));
  EXPECT_TRUE(open(empty_packet, key)->empty());
}

// ---- header ----

TEST(WireHeader, StampsIncreasingSequencesAndMonotonicTime) {
  HeaderStamp stamp(kSession, sender_of_slot(2));
  const Header first = stamp.next();
  const Header second = stamp.next();
  EXPECT_EQ(first.protocol_version(), kProtocolVersion);
  EXPECT_EQ(first.session(), kSession);
  EXPECT_EQ(first.sender(), 3u);
  EXPECT_EQ(first.sequence(), 1u);
  EXPECT_EQ(second.sequence(), 2u);
  EXPECT_LE(first.sender_time_ns(), second.sender_time_ns());
  EXPECT_LE(second.sender_time_ns(), monotonic_now_ns());
  stamp.set_session(99);
  Header third;
  stamp.stamp(third);
  EXPECT_EQ(third.session(), 99u);
  EXPECT_EQ(third.sequence(), 3u);
  EXPECT_EQ(stamp.last_sequence(), 3u);
  HeaderStamp other(kSession, kServerSender);  // one counter per channel
  EXPECT_EQ(other.next().sequence(), 1u);
}

// ---- replay window ----

TEST(WireReplayWindow, AcceptsNewAndInWindowUnseenRejectsDuplicatesAndOld) {
  ReplayWindow window;
  EXPECT_FALSE(window.highest());
  EXPECT_TRUE(window.accept(100));
  EXPECT_FALSE(window.accept(100));
  EXPECT_TRUE(window.accept(102));
  EXPECT_TRUE(window.accept(101));  // reordered but fresh
  EXPECT_FALSE(window.accept(101));
  EXPECT_EQ(*window.highest(), 102u);
  EXPECT_TRUE(window.accept(102 - 63));   // the oldest sequence still in the window
  EXPECT_FALSE(window.accept(102 - 64));  // just outside
  EXPECT_FALSE(window.fresh(102 - 63));
  EXPECT_TRUE(window.fresh(99));
  EXPECT_TRUE(window.accept(1000));  // a jump clears the window
  EXPECT_TRUE(window.accept(999));
  EXPECT_FALSE(window.accept(102));
  window.reset();
  EXPECT_TRUE(window.accept(5));
}

TEST(WireReplayWindow, MatchesASetOfSeenSequencesUnderRandomReordering) {
  std::mt19937 rng(11);
  ReplayWindow window;
  std::set<std::uint64_t> seen;
  std::uint64_t highest = 0;
  bool any = false;
  for (int i = 0; i < 20000; ++i) {
    const std::uint64_t base = any ? highest : 500;
    const std::uint64_t s = base + 10 - std::min<std::uint64_t>(base, rng() % 90);
    // Independent model: fresh = never seen and (nothing seen, above highest, or within 64 of it).
    const bool expected = !seen.count(s) && (!any || s > highest || highest - s < 64);
    ASSERT_EQ(window.accept(s), expected) << "sequence " << s << " highest " << highest;
    if (expected) {
      seen.insert(s);
      highest = any ? std::max(highest, s) : s;
      any = true;
    }
  }
}

// ---- datagrams ----

Datagram tool_datagram(std::uint64_t sequence, std::uint32_t sender = 1, std::uint64_t session = kSession) {
  Datagram d;
  Header* h = d.mutable_header();
  h->set_protocol_version(kProtocolVersion);
  h->set_session(session);
  h->set_sender(sender);
  h->set_sequence(sequence);
  h->set_sender_time_ns(123456789);
  ToolSample* tool = d.mutable_tool();
  tool->set_user(sender - 1);
  tool->set_sample_time_ns(-42);
  tool->mutable_position()->set_x(0.01);
  tool->mutable_position()->set_y(-0.02);
  tool->mutable_position()->set_z(-0.003);
  tool->set_valid(true);
  tool->set_buttons(5);
  return d;
}

struct InspectorRig {
  SessionKey key = key_of(1);
  DatagramInspector inspector{key, kSession};
  InspectorRig() {
    inspector.allow_sender(1);
    inspector.allow_sender(2);
  }
};

// Inspects `bytes` and checks that exactly the counter of `expected` (or accepted) rose by one.
void expect_outcome(DatagramInspector& inspector, const Bytes& bytes, std::optional<Rejection> expected,
                    const std::string& what) {
  const std::map<std::string, std::uint64_t> before = inspector.counters().snapshot();
  const std::optional<Datagram> result = inspector.inspect(bytes);
  const std::map<std::string, std::uint64_t> after = inspector.counters().snapshot();
  const std::string expected_name = expected ? std::string(to_string(*expected)) : "accepted";
  EXPECT_EQ(result.has_value(), !expected) << what;
  EXPECT_EQ(inspector.last_rejection(), expected) << what;
  ASSERT_EQ(before.size(), kRejectionCount + 1);
  for (const auto& [name, count] : after)
    EXPECT_EQ(count - before.at(name), name == expected_name ? 1u : 0u) << what << ": counter " << name;
}

TEST(WireDatagram, RoundTripsEveryBody) {
  const SessionKey key = key_of(1);
  Datagram tool = tool_datagram(7);
  const Bytes bytes = encode_datagram(tool, key);
  EXPECT_LE(bytes.size(), kMaxDatagramBytes);
  auto decoded = decode_datagram(bytes, key, kSession);
  ASSERT_TRUE(std::holds_alternative<Datagram>(decoded));
  const Datagram& d = std::get<Datagram>(decoded);
  EXPECT_EQ(d.header().sequence(), 7u);
  EXPECT_EQ(d.header().sender_time_ns(), 123456789);
  EXPECT_EQ(d.tool().position().y(), -0.02);
  EXPECT_EQ(d.tool().sample_time_ns(), -42);
  EXPECT_EQ(d.tool().buttons(), 5u);
  EXPECT_TRUE(d.tool().valid());

  Datagram force;
  *force.mutable_header() = tool.header();
  force.mutable_force()->set_user(1);
  to_wire(Eigen::Vector3d(0.5, -1.25, 3.0), force.mutable_force()->mutable_force());
  force.mutable_force()->set_ir_epoch(12);
  force.mutable_force()->set_flags(3);
  decoded = decode_datagram(encode_datagram(force, key), key);
  ASSERT_TRUE(std::holds_alternative<Datagram>(decoded));
  EXPECT_EQ(from_wire(std::get<Datagram>(decoded).force().force()), Eigen::Vector3d(0.5, -1.25, 3.0));
  EXPECT_EQ(std::get<Datagram>(decoded).force().ir_epoch(), 12u);

  Datagram pong;
  *pong.mutable_header() = tool.header();
  pong.mutable_pong()->set_client_send_ns(1);
  pong.mutable_pong()->set_server_receive_ns(std::numeric_limits<std::int64_t>::max());
  pong.mutable_pong()->set_server_send_ns(-3);
  decoded = decode_datagram(encode_datagram(pong, key), key);
  ASSERT_TRUE(std::holds_alternative<Datagram>(decoded));
  EXPECT_EQ(std::get<Datagram>(decoded).pong().server_receive_ns(), std::numeric_limits<std::int64_t>::max());

  // The in-place encoder produces the same bytes.
  Bytes reused;
  encode_datagram(tool, key, reused);
  EXPECT_EQ(reused, bytes);
}

TEST(WireDatagram, EncoderRefusesOversizedDatagrams) {
  Datagram d = tool_datagram(1);
  Datagram big;
  *big.mutable_header() = d.header();
  big.mutable_pong();
  // Unknown fields are kept and counted: grow the message past the limit with one.
  big.mutable_pong()->GetReflection()->MutableUnknownFields(big.mutable_pong())->AddLengthDelimited(99, std::string(1400, 'x'));
  EXPECT_THROW(encode_datagram(big, key_of(1)), cohaptic::Error);
}

TEST(WireDatagramInspector, AcceptsValidDatagramsAndCountsThem) {
  InspectorRig rig;
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(1), rig.key), std::nullopt, "first");
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(2), rig.key), std::nullopt, "second");
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(1, 2), rig.key), std::nullopt, "other sender");
  EXPECT_EQ(rig.inspector.counters().accepted(), 3u);
  EXPECT_EQ(rig.inspector.counters().rejected(), 0u);
  const auto snapshot = rig.inspector.counters().snapshot();
  for (Rejection r : kAllRejections) EXPECT_EQ(snapshot.at(std::string(to_string(r))), 0u);
  EXPECT_EQ(snapshot.at("accepted"), 3u);
}

TEST(WireDatagramInspector, RejectsEachHostileDatagramForItsReason) {
  InspectorRig rig;
  const Bytes valid = encode_datagram(tool_datagram(10), rig.key);

  expect_outcome(rig.inspector, encode_datagram(tool_datagram(10), key_of(2)), Rejection::bad_tag, "wrong key");
  for (std::size_t i : {std::size_t{0}, valid.size() / 2, valid.size() - kTagBytes - 1, valid.size() - 1}) {
    Bytes flipped = valid;
    flipped[i] ^= 0x20;
    expect_outcome(rig.inspector, flipped, Rejection::bad_tag, fmt::format("flipped byte {}", i));
  }
  for (std::size_t length : {std::size_t{0}, std::size_t{1}, kTagBytes - 1})
    expect_outcome(rig.inspector, Bytes(valid.begin(), valid.begin() + static_cast<long>(length)), Rejection::truncated,
                   fmt::format("truncated to {}", length));
  // Longer cuts lose the tag's alignment: the tail no longer authenticates the head.
  for (std::size_t length : {kTagBytes, kTagBytes + 5, valid.size() - 1})
    expect_outcome(rig.inspector, Bytes(valid.begin(), valid.begin() + static_cast<long>(length)), Rejection::bad_tag,
                   fmt::format("cut to {}", length));
  // Authentic bytes that are not a Datagram (field 1 with the invalid wire type 7).
  expect_outcome(rig.inspector, seal(Bytes{0x0f, 0x01, 0x02}, rig.key), Rejection::truncated, "unparsable payload");
  // An authentic payload cut short inside a field.
  {
    Datagram d = tool_datagram(10);
    std::string serialized = d.SerializeAsString();
    serialized.resize(serialized.size() - 3);
    expect_outcome(rig.inspector, seal(Bytes(serialized.begin(), serialized.end()), rig.key), Rejection::truncated,
                   "payload cut inside a field");
  }
  Bytes oversized = valid;
  oversized.resize(kMaxDatagramBytes + 1, 0);
  expect_outcome(rig.inspector, oversized, Rejection::oversized, "oversized");
  expect_outcome(rig.inspector, seal(Bytes(kMaxDatagramBytes - kTagBytes + 1, 0), rig.key), Rejection::oversized,
                 "oversized with a valid tag");

  Datagram version = tool_datagram(11);
  version.mutable_header()->set_protocol_version(kProtocolVersion - 1);  // an older peer
  expect_outcome(rig.inspector, encode_datagram(version, rig.key), Rejection::bad_version, "an older version");
  Datagram headless = tool_datagram(11);
  headless.clear_header();
  expect_outcome(rig.inspector, encode_datagram(headless, rig.key), Rejection::bad_version, "no header");
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(11, 1, kSession + 1), rig.key), Rejection::wrong_session,
                 "wrong session");
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(11, 7), rig.key), Rejection::unknown_sender,
                 "unknown sender");

  Datagram nan = tool_datagram(12);
  nan.mutable_tool()->mutable_position()->set_y(std::numeric_limits<double>::quiet_NaN());
  expect_outcome(rig.inspector, encode_datagram(nan, rig.key), Rejection::non_finite, "NaN tool position");
  Datagram invalid_nan = nan;
  invalid_nan.mutable_tool()->set_valid(false);
  expect_outcome(rig.inspector, encode_datagram(invalid_nan, rig.key), Rejection::non_finite, "NaN in an invalid sample");
  Datagram inf;
  *inf.mutable_header() = tool_datagram(13).header();
  to_wire(Eigen::Vector3d(0, std::numeric_limits<double>::infinity(), 0), inf.mutable_force()->mutable_force());
  expect_outcome(rig.inspector, encode_datagram(inf, rig.key), Rejection::non_finite, "infinite force");

  Datagram empty = tool_datagram(14);
  empty.clear_body();
  expect_outcome(rig.inspector, encode_datagram(empty, rig.key), Rejection::empty, "no body");

  // None of the rejected packets moved the window: the valid one is still fresh, once.
  expect_outcome(rig.inspector, valid, std::nullopt, "valid");
  expect_outcome(rig.inspector, valid, Rejection::replayed, "the same bytes again");
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(100), rig.key), std::nullopt, "jump to 100");
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(36), rig.key), Rejection::replayed, "older than the window");
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(37), rig.key), std::nullopt, "oldest in the window");
}

TEST(WireDatagramInspector, AcceptsReorderedFreshSequencesAndKeepsWindowsPerSender) {
  InspectorRig rig;
  for (std::uint64_t s : {20, 23, 21, 22, 5})
    expect_outcome(rig.inspector, encode_datagram(tool_datagram(s), rig.key), std::nullopt, fmt::format("sequence {}", s));
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(21), rig.key), Rejection::replayed, "21 again");
  // Sender 2 has its own window.
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(21, 2), rig.key), std::nullopt, "21 from sender 2");
  // A slot taken over by a new user starts afresh.
  rig.inspector.allow_sender(1);
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(1), rig.key), std::nullopt, "new user in slot 0");
  rig.inspector.forget_sender(2);
  EXPECT_FALSE(rig.inspector.allows(2));
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(22, 2), rig.key), Rejection::unknown_sender, "forgotten");
}

TEST(WireDatagramInspector, RejectedPacketsNeverAdvanceTheWindow) {
  InspectorRig rig;
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(5), rig.key), std::nullopt, "5");
  Datagram far_nan = tool_datagram(1000);
  far_nan.mutable_tool()->mutable_position()->set_x(std::numeric_limits<double>::infinity());
  expect_outcome(rig.inspector, encode_datagram(far_nan, rig.key), Rejection::non_finite, "authentic but infinite");
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(1000), key_of(9)), Rejection::bad_tag, "forged");
  EXPECT_EQ(*rig.inspector.window(1)->highest(), 5u);
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(6), rig.key), std::nullopt, "6 still fresh");
}

TEST(WireDatagramInspector, ExpectedSessionCanBeLearnedOrIgnored) {
  const SessionKey key = key_of(1);
  DatagramInspector inspector(key);  // no session expected yet
  inspector.allow_sender(kServerSender);
  expect_outcome(inspector, encode_datagram(tool_datagram(1, kServerSender, 77), key), std::nullopt, "any session");
  inspector.set_expected_session(78);
  expect_outcome(inspector, encode_datagram(tool_datagram(2, kServerSender, 77), key), Rejection::wrong_session, "77");
  expect_outcome(inspector, encode_datagram(tool_datagram(3, kServerSender, 78), key), std::nullopt, "78");
}

TEST(WireDatagramInspector, RandomBytesAndMutationsNeverThrowNorPassAsAuthentic) {
  InspectorRig rig;
  std::mt19937 rng(2024);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<std::size_t> length(0, 1500);
  for (int i = 0; i < 20000; ++i) {
    Bytes garbage(length(rng));
    for (auto& b : garbage) b = static_cast<std::uint8_t>(byte(rng));
    std::optional<Datagram> result;
    ASSERT_NO_THROW(result = rig.inspector.inspect(garbage));
    ASSERT_FALSE(result);
  }
  EXPECT_EQ(rig.inspector.counters().accepted(), 0u);
  EXPECT_EQ(rig.inspector.counters().rejected(), 20000u);

  const Bytes valid = encode_datagram(tool_datagram(50), rig.key);
  ASSERT_TRUE(rig.inspector.inspect(valid));
  int identical = 0;
  for (int i = 0; i < 20000; ++i) {
    Bytes m = valid;
    switch (rng() % 4) {
      case 0:  // flip one to four bits
        for (std::size_t k = 0, n = 1 + rng() % 4; k < n; ++k) m[rng() % m.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
        break;
      case 1:  // truncate
        m.resize(rng() % m.size());
        break;
      case 2:  // append
        for (std::size_t k = 0, n = 1 + rng() % 1400; k < n; ++k) m.push_back(static_cast<std::uint8_t>(byte(rng)));
        break;
      default:  // overwrite a run
        for (std::size_t k = rng() % m.size(), n = 1 + rng() % 16; k < m.size() && n > 0; ++k, --n)
          m[k] = static_cast<std::uint8_t>(byte(rng));
    }
    std::optional<Datagram> result;
    ASSERT_NO_THROW(result = rig.inspector.inspect(m));
    ASSERT_FALSE(result) << "mutation " << i << " accepted";
    if (m == valid) {
      ++identical;
      EXPECT_EQ(rig.inspector.last_rejection(), Rejection::replayed);
    } else {
      const Rejection r = *rig.inspector.last_rejection();
      ASSERT_TRUE(r == Rejection::bad_tag || r == Rejection::truncated || r == Rejection::oversized)
          << "mutation " << i << ": " << to_string(r);
    }
  }
  EXPECT_EQ(rig.inspector.counters().accepted(), 1u);
  EXPECT_EQ(rig.inspector.counters().rejected(), 40000u);
  EXPECT_EQ(rig.inspector.counters().count(Rejection::replayed), static_cast<std::uint64_t>(identical));
}

TEST(WireDatagramInspector, AuthenticGarbagePayloadsNeverThrow) {
  // A peer holding the key but sending nonsense: parse and every later check must hold.
  InspectorRig rig;
  std::mt19937 rng(7);
  const std::string valid = tool_datagram(1).SerializeAsString();
  for (int i = 0; i < 20000; ++i) {
    Bytes payload(valid.begin(), valid.end());
    if (i % 2) {
      payload.resize(rng() % 64);
      for (auto& b : payload) b = static_cast<std::uint8_t>(rng());
    } else {
      for (int k = 0; k < 3; ++k) payload[rng() % payload.size()] = static_cast<std::uint8_t>(rng());
    }
    ASSERT_NO_THROW(rig.inspector.inspect(seal(payload, rig.key)));
  }
  const RejectionCounters& c = rig.inspector.counters();
  EXPECT_EQ(c.accepted() + c.rejected(), 20000u);
  EXPECT_EQ(c.count(Rejection::bad_tag), 0u);
}

TEST(WireDatagramInspector, RejectionNamesAreTheEnumerators) {
  std::set<std::string> names;
  for (Rejection r : kAllRejections) names.insert(std::string(to_string(r)));
  EXPECT_EQ(names, (std::set<std::string>{"oversized", "truncated", "bad_tag", "bad_version", "wrong_session",
                                          "unknown_sender", "replayed", "non_finite", "empty"}));
}

// ---- TCP frames ----

Control control_with(std::uint64_t sequence, const std::string& text) {
  Control c;
  Header* h = c.mutable_header();
  h->set_protocol_version(kProtocolVersion);
  h->set_session(kSession);
  h->set_sequence(sequence);
  c.mutable_event()->set_kind("test");
  c.mutable_event()->set_text(text);
  return c;
}

std::string frame_error(FrameReader& reader) {
  try {
    while (reader.next()) {
    }
  } catch (const FrameError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(WireFrame, LayoutIsLengthPayloadTag) {
  const SessionKey key = key_of(5);
  const Control c = control_with(1, "hello");
  const Bytes frame = encode_frame(c, key);
  const std::string payload = c.SerializeAsString();
  ASSERT_EQ(frame.size(), 4 + payload.size() + kTagBytes);
  EXPECT_EQ(frame[0] | frame[1] << 8 | frame[2] << 16 | frame[3] << 24, static_cast<int>(payload.size()));
  EXPECT_EQ(Bytes(frame.begin() + 4, frame.end() - kTagBytes), Bytes(payload.begin(), payload.end()));
  const auto tag = authentication_tag(std::span(frame).first(4 + payload.size()), key);
  EXPECT_TRUE(std::equal(tag.begin(), tag.end(), frame.end() - kTagBytes));
}

TEST(WireFrame, ReaderReassemblesOneByteFeedsAndSeveralFramesPerFeed) {
  const SessionKey key = key_of(5);
  Bytes stream;
  for (int i = 1; i <= 3; ++i) {
    const Bytes frame = encode_frame(control_with(static_cast<std::uint64_t>(i), std::string(100 * static_cast<std::size_t>(i), static_cast<char>('a' + i))), key);
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
  FrameReader slow(key);
  std::vector<Control> received;
  for (std::uint8_t b : stream) {
    slow.feed(std::span(&b, 1));
    while (std::optional<Control> c = slow.next()) received.push_back(*c);
  }
  ASSERT_EQ(received.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(received[i].header().sequence(), static_cast<std::uint64_t>(i + 1));
    EXPECT_EQ(received[i].event().text(), std::string(100 * static_cast<std::size_t>(i + 1), static_cast<char>('a' + i + 1)));
  }
  EXPECT_EQ(slow.buffered(), 0u);

  FrameReader fast(key);
  fast.feed(stream);
  for (int i = 1; i <= 3; ++i) {
    std::optional<Control> c = fast.next();
    ASSERT_TRUE(c);
    EXPECT_EQ(c->header().sequence(), static_cast<std::uint64_t>(i));
  }
  EXPECT_FALSE(fast.next());

  // Arbitrary chunking, with a partial frame left over.
  FrameReader chunked(key);
  std::mt19937 rng(3);
  std::size_t at = 0, got = 0;
  while (at < stream.size() - 10) {
    const std::size_t n = std::min<std::size_t>(1 + rng() % 150, stream.size() - 10 - at);
    chunked.feed(std::span(stream).subspan(at, n));
    at += n;
    while (chunked.next()) ++got;
  }
  EXPECT_EQ(got, 2u);
  EXPECT_GT(chunked.buffered(), 0u);
  chunked.feed(std::span(stream).subspan(at));
  EXPECT_TRUE(chunked.next());
  EXPECT_FALSE(chunked.next());
}

TEST(WireFrame, ReaderCarriesAnIrAcrossTheStream) {
  const SessionKey key = key_of(5);
  Control c = control_with(1, "");
  c.mutable_ir()->set_format_version(2);
  for (int i = 0; i < 100000; ++i) c.mutable_ir()->mutable_fem()->add_m_tilde_f64(i * 0.5);
  FrameReader reader(key);
  reader.feed(encode_frame(c, key));
  const std::optional<Control> received = reader.next();
  ASSERT_TRUE(received);
  ASSERT_EQ(received->ir().fem().m_tilde_f64_size(), 100000);
  EXPECT_EQ(received->ir().fem().m_tilde_f64(99999), 99999 * 0.5);
}

TEST(WireFrame, ReaderRejectsOversizedLengthBeforeReceivingThePayload) {
  FrameReader reader(key_of(5), 1000);
  const Bytes length = {0xe9, 0x03, 0x00, 0x00};  // 1001
  reader.feed(length);
  const std::string error = frame_error(reader);
  EXPECT_NE(error.find("declared payload length 1001 exceeds the limit of 1000"), std::string::npos) << error;
  // Sticky: the stream cannot be resynchronised.
  reader.feed(encode_frame(control_with(1, "x"), key_of(5)));
  EXPECT_THROW(reader.next(), FrameError);

  FrameReader default_limit(key_of(5));
  default_limit.feed(Bytes{0xff, 0xff, 0xff, 0xff});
  EXPECT_NE(frame_error(default_limit).find("exceeds the limit of 67108864"), std::string::npos);
}

TEST(WireFrame, ReaderRejectsCorruptedTagsWrongKeysAndBadPayloads) {
  const SessionKey key = key_of(5);
  Bytes frame = encode_frame(control_with(1, "hello"), key);
  frame[frame.size() - 1] ^= 0x80;
  FrameReader corrupted(key);
  corrupted.feed(frame);
  EXPECT_NE(frame_error(corrupted).find("bad authentication tag"), std::string::npos);

  Bytes length_changed = encode_frame(control_with(1, "hello"), key);
  length_changed.push_back(0);  // one more byte, and the length claims it: the tag no longer matches
  length_changed[0] = static_cast<std::uint8_t>(length_changed[0] + 1);
  FrameReader lengthened(key);
  lengthened.feed(length_changed);
  EXPECT_NE(frame_error(lengthened).find("bad authentication tag"), std::string::npos);

  FrameReader wrong_key(key);
  wrong_key.feed(encode_frame(control_with(1, "hello"), key_of(6)));
  EXPECT_NE(frame_error(wrong_key).find("bad authentication tag"), std::string::npos);

  // An authentic frame whose payload is not a Control.
  Bytes garbage = {3, 0, 0, 0, 0x0f, 0x01, 0x02};
  const auto tag = authentication_tag(garbage, key);
  garbage.insert(garbage.end(), tag.begin(), tag.end());
  FrameReader unparsable(key);
  unparsable.feed(garbage);
  EXPECT_NE(frame_error(unparsable).find("not a Control message"), std::string::npos);
}

TEST(WireFrame, ReaderChecksVersionBodyAndSequence) {
  const SessionKey key = key_of(5);
  Control v2 = control_with(1, "x");
  v2.mutable_header()->set_protocol_version(kProtocolVersion - 1);
  FrameReader version(key);
  version.feed(encode_frame(v2, key));
  EXPECT_NE(frame_error(version).find(fmt::format("protocol version {}, expected {}", kProtocolVersion - 1, kProtocolVersion)),
            std::string::npos);

  Control bodiless = control_with(1, "x");
  bodiless.clear_body();
  FrameReader empty(key);
  empty.feed(encode_frame(bodiless, key));
  EXPECT_NE(frame_error(empty).find("without a body"), std::string::npos);

  FrameReader replay(key);
  replay.feed(encode_frame(control_with(4, "x"), key));
  replay.feed(encode_frame(control_with(9, "x"), key));
  replay.feed(encode_frame(control_with(9, "x"), key));
  EXPECT_TRUE(replay.next());
  EXPECT_TRUE(replay.next());
  EXPECT_NE(frame_error(replay).find("sequence 9 is not above the previous frame's 9"), std::string::npos);
}

TEST(WireFrame, ReaderSurvivesRandomStreams) {
  const SessionKey key = key_of(5);
  std::mt19937 rng(17);
  const Bytes valid = encode_frame(control_with(1, "hello"), key);
  for (int i = 0; i < 2000; ++i) {
    FrameReader reader(key, 4096);
    Bytes stream = valid;
    if (i % 2) {
      stream.resize(rng() % 200);
      for (auto& b : stream) b = static_cast<std::uint8_t>(rng());
    } else {
      stream[rng() % stream.size()] ^= static_cast<std::uint8_t>(1 + rng() % 255);
    }
    reader.feed(stream);
    try {
      while (reader.next()) ADD_FAILURE() << "stream " << i << " yielded a forged frame";
    } catch (const FrameError&) {
    }
  }
}

// ---- IR ----

testing::CubeSceneOptions small_cube() {
  testing::CubeSceneOptions options;
  options.divisions = 3;
  return options;
}

struct IrRig {
  testing::CubeRig rig;
  explicit IrRig(IrPrecision precision) : rig(small_cube()) {
    SimulationOptions options;
    options.ir.precision = precision;
    Simulation simulation(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(2), options);
    simulation.set_tool(0, {0, 0, -0.002});
    simulation.set_tool(1, {0.03, 0, -0.002});
    simulation.step(0);
    ir = simulation.ir(0)->ir;
  }
  cohaptic::IntermediateRepresentation ir;
};

const cohaptic::IntermediateRepresentation& sample_ir(IrPrecision precision) {
  static IrRig f64(IrPrecision::f64);
  static IrRig f32(IrPrecision::f32);
  return precision == IrPrecision::f64 ? f64.ir : f32.ir;
}

template <typename Derived>
bool bit_equal(const Eigen::DenseBase<Derived>& a, const Eigen::DenseBase<Derived>& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.derived().data(), b.derived().data(), static_cast<std::size_t>(a.size()) * sizeof(double)) == 0;
}

bool bit_equal(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::memcmp(a.data(), b.data(), 3 * sizeof(double)) == 0; }

void expect_same_ir(const cohaptic::IntermediateRepresentation& envelope_a,
                    const cohaptic::IntermediateRepresentation& envelope_b) {
  EXPECT_EQ(envelope_a.epoch, envelope_b.epoch);
  EXPECT_EQ(std::memcmp(&envelope_a.simulation_time, &envelope_b.simulation_time, sizeof(double)), 0);
  EXPECT_EQ(envelope_a.user, envelope_b.user);
  EXPECT_EQ(envelope_a.object, envelope_b.object);
  EXPECT_EQ(envelope_a.tool_radius, envelope_b.tool_radius);
  EXPECT_EQ(envelope_a.force_limit, envelope_b.force_limit);
  const CondensedFemIr& a = condensed_fem(envelope_a);
  const CondensedFemIr& b = condensed_fem(envelope_b);
  EXPECT_EQ(a.contact_model, b.contact_model);
  EXPECT_EQ(a.precision, b.precision);
  EXPECT_EQ(a.node_ids, b.node_ids);
  EXPECT_EQ(a.fixed_axes, b.fixed_axes);
  EXPECT_TRUE(bit_equal(a.rest_positions, b.rest_positions));
  EXPECT_EQ(a.patch_node_count, b.patch_node_count);
  EXPECT_EQ(a.row_node_count, b.row_node_count);
  ASSERT_EQ(a.patch.size(), b.patch.size());
  for (std::size_t i = 0; i < a.patch.size(); ++i) {
    EXPECT_EQ(a.patch[i].nodes, b.patch[i].nodes);
    EXPECT_EQ(a.patch[i].surface_index, b.patch[i].surface_index);
    EXPECT_TRUE(bit_equal(a.patch[i].normal, b.patch[i].normal));
    EXPECT_EQ(a.patch[i].neighbours, b.patch[i].neighbours);
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(bit_equal(a.patch[i].edge_normals[k], b.patch[i].edge_normals[k]));
  }
  EXPECT_TRUE(bit_equal(a.patch_vertex_normals, b.patch_vertex_normals));
  ASSERT_EQ(a.guard.size(), b.guard.size());
  for (std::size_t i = 0; i < a.guard.size(); ++i) {
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(bit_equal(a.guard[i].corners[k], b.guard[i].corners[k]));
    EXPECT_TRUE(bit_equal(a.guard[i].normal, b.guard[i].normal));
  }
  ASSERT_EQ(a.remotes.size(), b.remotes.size());
  for (std::size_t i = 0; i < a.remotes.size(); ++i) {
    EXPECT_EQ(a.remotes[i].user, b.remotes[i].user);
    EXPECT_EQ(a.remotes[i].nodes, b.remotes[i].nodes);
    EXPECT_TRUE(bit_equal(a.remotes[i].normal, b.remotes[i].normal));
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(bit_equal(a.remotes[i].edge_normals[k], b.remotes[i].edge_normals[k]));
      EXPECT_TRUE(bit_equal(a.remotes[i].vertex_normals[k], b.remotes[i].vertex_normals[k]));
    }
    EXPECT_EQ(a.remotes[i].tool_radius, b.remotes[i].tool_radius);
  }
  EXPECT_TRUE(bit_equal(a.m_tilde, b.m_tilde));
  EXPECT_TRUE(bit_equal(a.boundary_displacement, b.boundary_displacement));
}

// Through bytes, as it travels: to_wire, a Control frame, FrameReader, from_wire.
cohaptic::IntermediateRepresentation through_the_wire(const cohaptic::IntermediateRepresentation& ir) {
  const SessionKey key = key_of(8);
  Control control;
  HeaderStamp(kSession, kServerSender).stamp(*control.mutable_header());
  to_wire(ir, control.mutable_ir());
  FrameReader reader(key);
  reader.feed(encode_frame(control, key));
  std::optional<Control> received = reader.next();
  EXPECT_TRUE(received);
  return from_wire(received->ir());
}

TEST(WireIr, RoundTripIsBitExactInDouble) {
  cohaptic::IntermediateRepresentation ir = sample_ir(IrPrecision::f64);
  CondensedFemIr& fem = condensed_fem(ir);
  ASSERT_FALSE(fem.remotes.empty());
  ASSERT_GT(fem.m_tilde.size(), 0);
  ir.epoch = 0xfedcba9876543210ull;
  ir.simulation_time = 1.0 / 3.0;
  ir.object = 3;
  ir.force_limit = std::numeric_limits<double>::infinity();  // "no limit" travels too
  fem.m_tilde(0, 0) = std::nextafter(fem.m_tilde(0, 0), 0.0);  // a value float would not keep
  const IntermediateRepresentation wire_ir = to_wire(ir);
  EXPECT_EQ(wire_ir.format_version(), 2u);
  const CondensedFem& w = wire_ir.fem();
  EXPECT_EQ(w.m_tilde_f64_size(), fem.m_tilde.size());
  EXPECT_EQ(w.m_tilde_f32_size(), 0);
  EXPECT_EQ(w.m_rows(), static_cast<std::uint32_t>(fem.m_tilde.rows()));
  // Column-major: entry (1, 0) follows (0, 0).
  EXPECT_EQ(w.m_tilde_f64(1), fem.m_tilde(1, 0));
  expect_same_ir(through_the_wire(ir), ir);

  // The received IR evaluates to the same force as the original.
  const PreparedIR original = prepare_ir(ir);
  const PreparedIR received = prepare_ir(through_the_wire(ir));
  const std::vector<Eigen::Vector3d> remote = {Eigen::Vector3d(0.03, 0, -0.002)};
  const Eigen::Vector3d tool(0.001, 0.0005, -0.003);
  EXPECT_TRUE(bit_equal(testing::evaluate_static(received, tool, remote).force, testing::evaluate_static(original, tool, remote).force));
}

TEST(WireIr, RoundTripIsExactInFloat) {
  const cohaptic::IntermediateRepresentation& ir = sample_ir(IrPrecision::f32);
  const CondensedFemIr& fem = condensed_fem(ir);
  ASSERT_EQ(fem.precision, IrPrecision::f32);
  const IntermediateRepresentation wire_ir = to_wire(ir);
  const CondensedFem& w = wire_ir.fem();
  EXPECT_EQ(w.m_tilde_f64_size(), 0);
  ASSERT_EQ(w.m_tilde_f32_size(), fem.m_tilde.size());
  for (Eigen::Index i = 0; i < fem.m_tilde.size(); ++i)
    ASSERT_EQ(static_cast<double>(w.m_tilde_f32(static_cast<int>(i))), fem.m_tilde.data()[i]);
  expect_same_ir(through_the_wire(ir), ir);
  // Half the bytes of the double version for M~.
  EXPECT_LT(wire_ir.ByteSizeLong(), to_wire(sample_ir(IrPrecision::f64)).ByteSizeLong());
}

TEST(WireIr, FromWireRejectsEveryInconsistency) {
  const IntermediateRepresentation valid = to_wire(sample_ir(IrPrecision::f64));
  ASSERT_NO_THROW(from_wire(valid));
  ASSERT_GT(valid.fem().remotes_size(), 0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    const char* name;
    std::function<void(IntermediateRepresentation&)> corrupt;
    const char* message;
  };
  const std::vector<Case> cases = {
      {"format version", [](auto& w) { w.set_format_version(1); }, "format version 1, expected 2"},
      {"no body", [](auto& w) { w.clear_fem(); }, "no body of a kind this build knows"},
      {"fixed_axes length", [](auto& w) { w.mutable_fem()->mutable_fixed_axes()->pop_back(); }, "fixed_axes bytes for"},
      {"fixed_axes mask", [](auto& w) { (*w.mutable_fem()->mutable_fixed_axes())[0] = 8; }, "not a mask"},
      {"row count", [](auto& w) { w.mutable_fem()->set_row_node_count(static_cast<std::uint32_t>(w.fem().node_ids_size() + 1)); }, "exceeds the"},
      {"patch count", [](auto& w) { w.mutable_fem()->set_patch_node_count(w.fem().row_node_count() + 1); }, "exceeds row_node_count"},
      {"rest positions", [](auto& w) { w.mutable_fem()->mutable_rest_positions()->RemoveLast(); }, "rest_positions has"},
      {"NaN rest position", [nan](auto& w) { w.mutable_fem()->set_rest_positions(4, nan); }, "rest_positions[4] is not finite"},
      {"empty patch", [](auto& w) { w.mutable_fem()->clear_patch(); }, "no triangle"},
      {"two-node triangle", [](auto& w) { w.mutable_fem()->mutable_patch(0)->mutable_nodes()->RemoveLast(); }, "patch[0].nodes has 2 entries"},
      {"node outside patch", [](auto& w) { w.mutable_fem()->mutable_patch(0)->set_nodes(1, w.fem().patch_node_count()); }, "outside the patch"},
      {"neighbour out of range", [](auto& w) { w.mutable_fem()->mutable_patch(0)->set_neighbours(2, w.fem().patch_size()); }, "neighbours[2]"},
      {"neighbour below -1", [](auto& w) { w.mutable_fem()->mutable_patch(0)->set_neighbours(0, -2); }, "neighbours[0] = -2"},
      {"two edge normals", [](auto& w) { w.mutable_fem()->mutable_patch(0)->mutable_edge_normals()->RemoveLast(); }, "edge_normals has 2"},
      {"NaN normal", [nan](auto& w) { w.mutable_fem()->mutable_patch(0)->mutable_normal()->set_z(nan); }, "patch[0].normal has a non-finite"},
      {"negative surface index", [](auto& w) { w.mutable_fem()->mutable_patch(0)->set_surface_index(-1); }, "surface_index is negative"},
      {"vertex normals", [](auto& w) { w.mutable_fem()->add_patch_vertex_normals(0); }, "patch_vertex_normals has"},
      {"guard corners", [](auto& w) { w.mutable_fem()->add_guard()->add_corners(); }, "corners has 1 entries"},
      {"remote node", [](auto& w) { w.mutable_fem()->mutable_remotes(0)->set_nodes(0, w.fem().row_node_count()); }, "outside the contact nodes"},
      {"remote vertex normals", [](auto& w) { w.mutable_fem()->mutable_remotes(0)->clear_vertex_normals(); }, "vertex_normals has 0"},
      {"remote radius", [](auto& w) { w.mutable_fem()->mutable_remotes(0)->set_tool_radius(-1); }, "tool_radius -1"},
      {"contact model", [](auto& w) { w.mutable_fem()->set_contact_model(static_cast<CondensedFem::ContactModel>(7)); }, "unknown contact model 7"},
      {"tool radius", [nan](auto& w) { w.set_tool_radius(nan); }, "tool_radius nan"},
      {"force limit", [](auto& w) { w.set_force_limit(-1); }, "force_limit -1"},
      {"simulation time", [](auto& w) { w.set_simulation_time(std::numeric_limits<double>::infinity()); }, "simulation_time"},
      {"m_rows", [](auto& w) { w.mutable_fem()->set_m_rows(w.fem().m_rows() - 1); }, "m_rows"},
      {"m_cols", [](auto& w) { w.mutable_fem()->set_m_cols(w.fem().m_cols() + 3); }, "m_cols"},
      {"M~ length", [](auto& w) { w.mutable_fem()->mutable_m_tilde_f64()->RemoveLast(); }, "M~ has"},
      {"NaN in M~", [nan](auto& w) { w.mutable_fem()->set_m_tilde_f64(5, nan); }, "m_tilde_f64[5] is not finite"},
      {"u_B length", [](auto& w) { w.mutable_fem()->add_boundary_displacement_f64(0); }, "u_B has 1 values, expected 0"},
      {"mixed precision", [](auto& w) { w.mutable_fem()->add_boundary_displacement_f32(0); }, "mix f64 and f32"},
      {"M~ in both", [](auto& w) { w.mutable_fem()->add_m_tilde_f32(1); }, "mix f64 and f32"},
      {"user", [](auto& w) { w.set_user(0x80000000u); }, "user = 2147483648"},
  };
  for (const Case& c : cases) {
    IntermediateRepresentation w = valid;
    c.corrupt(w);
    const std::string error = error_of([&] { from_wire(w); });
    EXPECT_NE(error.find(c.message), std::string::npos) << c.name << ": " << error;
    EXPECT_EQ(error.rfind("intermediate representation: ", 0), 0u) << c.name << ": " << error;
  }
}

TEST(WireIr, FromWireSurvivesMutatedBytes) {
  const std::string valid = to_wire(sample_ir(IrPrecision::f64)).SerializeAsString();
  std::mt19937 rng(99);
  int parsed = 0, converted = 0;
  for (int i = 0; i < 3000; ++i) {
    std::string bytes = valid;
    for (std::size_t k = 0, n = 1 + rng() % 6; k < n; ++k) bytes[rng() % bytes.size()] = static_cast<char>(rng());
    if (i % 3 == 0) bytes.resize(rng() % bytes.size());
    IntermediateRepresentation w;
    if (!w.ParseFromString(bytes)) continue;
    ++parsed;
    try {
      const cohaptic::IntermediateRepresentation ir = from_wire(w);
      ++converted;
      // Whatever passed is self-consistent enough for the evaluator's own checks.
      EXPECT_EQ(condensed_fem(ir).m_tilde.size(),
                static_cast<Eigen::Index>(w.fem().m_tilde_f64_size() + w.fem().m_tilde_f32_size()));
    } catch (const cohaptic::Error&) {
    }
  }
  EXPECT_GT(parsed, 100);
  std::printf("  %d of 3000 mutations parsed, %d of them passed validation\n", parsed, converted);
}

// ---- surface mesh ----

TEST(WireSurfaceMesh, BoxSurfaceInCompactNumbering) {
  const Model model = build_model(parse_scene(testing::cube_scene_yaml(small_cube()), "cube.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  const SurfaceMesh message = surface_mesh_message(body);
  // A 3 x 3 x 3 grid of cells: 4^3 - 2^3 surface nodes, 6 faces x 9 squares x 2 triangles.
  ASSERT_EQ(message.vertices_size(), 3 * 56);
  ASSERT_EQ(message.node_ids_size(), 56);
  ASSERT_EQ(message.triangles_size(), 3 * 108);
  const Eigen::Vector3d centre(0, 0, -0.065);
  std::set<std::int64_t> ids;
  for (int i = 0; i < 56; ++i) {
    const Eigen::Vector3d v(message.vertices(3 * i), message.vertices(3 * i + 1), message.vertices(3 * i + 2));
    EXPECT_NEAR((v - centre).lpNorm<Eigen::Infinity>(), 0.065, 1e-12) << "vertex " << i << " is not on the cube's faces";
    ids.insert(message.node_ids(i));
    const int node = node_index_from_tag(body.mesh, message.node_ids(i));
    ASSERT_GE(node, 0);
    EXPECT_EQ(body.mesh.nodes.col(node), v);  // the id names the node at that position
  }
  EXPECT_EQ(ids.size(), 56u);
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  double area = 0;
  for (int t = 0; t < 108; ++t) {
    Eigen::Vector3d p[3];
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = message.triangles(3 * t + k);
      ASSERT_LT(v, 56u);
      p[k] = Eigen::Vector3d(message.vertices(3 * v), message.vertices(3 * v + 1), message.vertices(3 * v + 2));
      const std::uint32_t w = message.triangles(3 * t + (k + 1) % 3);
      edges.insert({std::min(v, w), std::max(v, w)});
    }
    const Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]);
    EXPECT_GT(n.dot((p[0] + p[1] + p[2]) / 3 - centre), 0) << "triangle " << t << " faces inwards";
    area += 0.5 * n.norm();
  }
  EXPECT_EQ(56 - static_cast<int>(edges.size()) + 108, 2);  // a closed sphere-like surface
  EXPECT_NEAR(area, 6 * 0.13 * 0.13, 1e-12);

  const ReceivedSurface received = from_wire(message);
  EXPECT_EQ(received.surface.vertex_count(), 56);
  EXPECT_EQ(received.surface.triangle_count(), 108);
  EXPECT_EQ(received.node_ids[7], message.node_ids(7));
  EXPECT_EQ(received.surface.triangles[5][1], static_cast<int>(message.triangles(16)));

  SurfaceMesh bad = message;
  bad.set_triangles(10, 56);
  EXPECT_NE(error_of([&] { from_wire(bad); }).find("triangle 3 refers to vertex 56"), std::string::npos);
  bad = message;
  bad.mutable_node_ids()->RemoveLast();
  EXPECT_NE(error_of([&] { from_wire(bad); }).find("55 node ids for 56 vertices"), std::string::npos);
  bad = message;
  bad.set_vertices(0, std::numeric_limits<double>::quiet_NaN());
  EXPECT_NE(error_of([&] { from_wire(bad); }).find("vertex 0 has a non-finite"), std::string::npos);
}

TEST(WireVec3, ConvertsBitForBit) {
  const Eigen::Vector3d v(0.1, -std::numeric_limits<double>::denorm_min(), 1e300);
  EXPECT_TRUE(bit_equal(from_wire(to_wire(v)), v));
  Vec3 absent;
  EXPECT_EQ(from_wire(absent), Eigen::Vector3d::Zero());
  absent.set_y(std::numeric_limits<double>::infinity());
  EXPECT_FALSE(is_finite(absent));
}

}  // namespace
}  // namespace cohaptic::wire
