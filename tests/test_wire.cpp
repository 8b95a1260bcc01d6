// The wire layer (proto/wire/): key files (both kinds, and the modes refused), traffic-key
// derivation against BLAKE2b computed directly, the AEAD seal against libsodium's own
// XChaCha20-Poly1305 over the documented nonce, the datagram codec with its replay window
// and rejection counters (every reason with a hand-made hostile packet, another slot's
// key, and random garbage), the TCP frame reader with the greeting, and the IR and surface
// conversions.
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
#include "common/util/monotonic_clock.h"
#include "proto/wire/aead.h"
#include "proto/wire/datagram_codec.h"
#include "proto/wire/envelope.h"
#include "proto/wire/frame_codec.h"
#include "proto/wire/header.h"
#include "proto/wire/ir_convert.h"
#include "proto/wire/replay_window.h"
#include "proto/wire/sealer.h"
#include "proto/wire/session_key.h"
#include "proto/wire/traffic_keys.h"
#include "support/cube_scene.h"
#include "support/evaluate_static.h"

namespace cohaptic::wire {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr std::uint64_t kSession = 0x5e5510'0001;
constexpr std::uint64_t kSalt = 0x5a17'0000'0000'00abull;

TrafficKey key_of(std::uint8_t seed) {
  TrafficKey key;
  for (std::size_t i = 0; i < key.bytes.size(); ++i)
    key.bytes[i] = static_cast<std::uint8_t>(seed + 7 * i);
  return key;
}

// ---- key files ----

class TempDir {
 public:
  TempDir() {
    path_ = std::filesystem::temp_directory_path() /
            fmt::format("cohaptic-wire-{}-{}", ::getpid(), counter_++);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  static inline int counter_ = 0;
  std::filesystem::path path_;
};

// Writes a key file with `mode` (0600 unless said otherwise: key files must be private).
void write_text(const std::filesystem::path& file, const std::string& text, ::mode_t mode = 0600) {
  {
    std::ofstream out(file, std::ios::binary);
    out << text;
  }
  ::chmod(file.c_str(), mode);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const cohaptic::Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(WireKeyFile, LoadsHexWithWhitespaceInEitherCase) {
  TempDir dir;
  write_text(dir / "key.txt",
             "  00112233445566778899AABBCCDDEEFF\n\t00112233445566778899aabbccddeeff  \r\n");
  const SessionKey key = load_session_key(dir / "key.txt");
  for (std::size_t i = 0; i < 16; ++i) {
    EXPECT_EQ(key.bytes[i], static_cast<std::uint8_t>(0x11 * i));
    EXPECT_EQ(key.bytes[16 + i], static_cast<std::uint8_t>(0x11 * i));
  }
  EXPECT_EQ(to_hex(key), "00112233445566778899aabbccddeeff00112233445566778899aabbccddeeff");
}

TEST(WireKeyFile, RejectsMalformedFilesNamingFileAndProblem) {
  TempDir dir;
  write_text(dir / "short.txt", "0123456789ab\n");
  const std::string short_error = error_of([&] { load_session_key(dir / "short.txt"); });
  EXPECT_NE(short_error.find("short.txt: expected 64 hexadecimal characters, found 12"),
            std::string::npos)
      << short_error;

  write_text(dir / "long.txt", std::string(66, 'a'));
  EXPECT_NE(error_of([&] { load_session_key(dir / "long.txt"); }).find("found 66"),
            std::string::npos);

  write_text(dir / "bad.txt", std::string(40, 'a') + "g" + std::string(23, 'a'));
  const std::string bad_error = error_of([&] { load_session_key(dir / "bad.txt"); });
  EXPECT_NE(bad_error.find("bad.txt"), std::string::npos) << bad_error;
  EXPECT_NE(bad_error.find("'g'"), std::string::npos) << bad_error;
  EXPECT_NE(bad_error.find("column 41"), std::string::npos) << bad_error;

  write_text(dir / "zero.txt", std::string(64, '0'));
  EXPECT_NE(error_of([&] { load_session_key(dir / "zero.txt"); }).find("all zeros"),
            std::string::npos);

  write_text(dir / "slot.txt", "participant two\n" + std::string(64, 'a'));
  const std::string slot_error = error_of([&] { load_key_file(dir / "slot.txt"); });
  EXPECT_NE(slot_error.find("slot.txt: line 1: expected `participant K`"), std::string::npos)
      << slot_error;
  write_text(dir / "slot_hex.txt", "participant 2\n" + std::string(63, 'a') + "x");
  const std::string slot_hex_error = error_of([&] { load_key_file(dir / "slot_hex.txt"); });
  EXPECT_NE(slot_hex_error.find("'x' at line 2 column 64"), std::string::npos) << slot_hex_error;

  const std::string missing = error_of([&] { load_session_key(dir / "missing.txt"); });
  EXPECT_NE(missing.find("missing.txt"), std::string::npos) << missing;
  const std::string directory = error_of([&] { load_session_key(dir / ""); });
  EXPECT_NE(directory.find("regular file"), std::string::npos) << directory;
}

TEST(WireKeyFile, RefusesAKeyFileItsGroupOrOthersMayUse) {
  TempDir dir;
  const std::string hex(64, 'c');
  for (const ::mode_t mode : {0644, 0640, 0604, 0660, 0602, 0610, 0601}) {
    const std::string name = fmt::format("key-{:o}", mode);
    write_text(dir / name, hex, mode);
    const std::string error = error_of([&] { load_key_file(dir / name); });
    EXPECT_NE(error.find(fmt::format("mode {:04o}", mode)), std::string::npos) << error;
    EXPECT_NE(error.find("chmod 600"), std::string::npos) << error;
  }
  for (const ::mode_t mode : {0600, 0400}) {
    write_text(dir / "private", hex, mode);
    EXPECT_EQ(to_hex(load_session_key(dir / "private")), hex) << fmt::format("mode {:o}", mode);
    std::filesystem::remove(dir / "private");
  }
}

TEST(WireKeyFile, WritesFreshPrivateRandomKeys) {
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

TEST(WireKeyFile, ParticipantKeyFilesHoldTheSlotAndItsDerivedKey) {
  TempDir dir;
  write_session_key(dir / "session.key");
  const SessionKey session = load_session_key(dir / "session.key");
  write_participant_key(dir / "alice.key", session, 3);
  struct stat st {};
  ASSERT_EQ(::stat((dir / "alice.key").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  std::ifstream in(dir / "alice.key");
  std::string first_line;
  std::getline(in, first_line);
  EXPECT_EQ(first_line, "participant 3");
  const auto loaded = load_key_file(dir / "alice.key");
  ASSERT_TRUE(std::holds_alternative<ParticipantKey>(loaded));
  EXPECT_EQ(std::get<ParticipantKey>(loaded).slot, 3u);
  EXPECT_EQ(std::get<ParticipantKey>(loaded).key.bytes, participant_key(session, 3).bytes);
  // The server needs the session key: a participant's file is refused, naming its slot.
  const std::string error = error_of([&] { load_session_key(dir / "alice.key"); });
  EXPECT_NE(error.find("participant 3's key file"), std::string::npos) << error;
  EXPECT_TRUE(std::holds_alternative<SessionKey>(load_key_file(dir / "session.key")));
}

TEST(WireKeyFile, DevelopmentKeyIsTheDocumentedText) {
  const std::string text = "cohaptic-development-key-public!";
  const SessionKey key = development_key();
  EXPECT_EQ(std::string(key.bytes.begin(), key.bytes.end()), text);
  EXPECT_EQ(to_hex(key), "636f6861707469632d646576656c6f706d656e742d6b65792d7075626c696321");
}

// ---- traffic keys ----

// crypto_kdf as documented, computed directly: BLAKE2b-256 keyed with the master key, the
// sender id as the little-endian salt, "cohaptic" as the personalisation.
std::array<std::uint8_t, 32> blake2b_kdf(const SessionKey& master, std::uint64_t id) {
  std::array<std::uint8_t, crypto_generichash_blake2b_SALTBYTES> salt{};
  for (int i = 0; i < 8; ++i)
    salt[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(id >> (8 * i));
  std::array<std::uint8_t, crypto_generichash_blake2b_PERSONALBYTES> personal{};
  std::memcpy(personal.data(), "cohaptic", 8);
  std::array<std::uint8_t, 32> out{};
  crypto_generichash_blake2b_salt_personal(out.data(), out.size(), nullptr, 0, master.bytes.data(),
                                           master.bytes.size(), salt.data(), personal.data());
  return out;
}

TEST(WireTrafficKeys, EachSenderHasItsOwnKeyDerivedAsDocumented) {
  const SessionKey session = development_key();
  std::set<std::array<std::uint8_t, 32>> keys;
  for (std::uint32_t slot = 0; slot < 8; ++slot) {
    const TrafficKey key = participant_key(session, slot);
    EXPECT_EQ(key.bytes, blake2b_kdf(session, slot + 1)) << "slot " << slot;
    keys.insert(key.bytes);
  }
  EXPECT_EQ(joining_key(session).bytes, blake2b_kdf(session, kJoiningSender));
  keys.insert(joining_key(session).bytes);
  keys.insert(session.bytes);
  EXPECT_EQ(keys.size(), 10u);  // all different, and none is the session key itself
  SessionKey other = session;
  other.bytes[31] ^= 1;
  EXPECT_NE(participant_key(other, 0).bytes, participant_key(session, 0).bytes);
}

TEST(WireTrafficKeys, AParticipantKeyOpensItsOwnSlotOnlyAndTheSessionKeyAny) {
  const SessionKey session = development_key();
  const ClientKeys holder(session);
  EXPECT_FALSE(holder.fixed_slot());
  EXPECT_EQ(holder.join_sender(), kJoiningSender);
  EXPECT_EQ(holder.join_key().bytes, joining_key(session).bytes);
  EXPECT_EQ(holder.slot_key(5)->bytes, participant_key(session, 5).bytes);

  const ClientKeys participant(ParticipantKey{2, participant_key(session, 2)});
  EXPECT_EQ(participant.fixed_slot(), 2u);
  EXPECT_EQ(participant.join_sender(), sender_of_slot(2));
  EXPECT_EQ(participant.join_key().bytes, participant_key(session, 2).bytes);
  EXPECT_EQ(participant.slot_key(2)->bytes, participant_key(session, 2).bytes);
  EXPECT_FALSE(participant.slot_key(1));
}

// ---- sealing ----

TEST(WireAead, SealIsXChaCha20Poly1305OverTheDocumentedNonce) {
  const TrafficKey key = key_of(3);
  const Envelope envelope{kProtocolVersion, kEncryptedFlag, 7, 0x0102030405060708ull,
                          0x1112131415161718ull};
  const Bytes body = {1, 2, 3, 4, 5, 250, 0, 17};
  Bytes message(kEnvelopeBytes + body.size() + kTagBytes);
  write_envelope(envelope, message.data());
  std::copy(body.begin(), body.end(), message.begin() + kEnvelopeBytes);
  seal_in_place(message, kEnvelopeBytes, make_nonce(Channel::datagram, envelope), key, true);
  EXPECT_FALSE(
      std::equal(body.begin(), body.end(), message.begin() + kEnvelopeBytes));  // encrypted

  // The documented layout of the envelope and the nonce, byte by byte.
  EXPECT_EQ(Bytes(message.begin(), message.begin() + kEnvelopeBytes),
            (Bytes{3, 1, 7, 0,    0,    0,    8,    7,    6,    5,    4,
                   3, 2, 1, 0x18, 0x17, 0x16, 0x15, 0x14, 0x13, 0x12, 0x11}));
  const Bytes nonce = {8, 7, 6, 5, 4,    3,    2,    1,    7,    0,    0,    0,
                       1, 0, 0, 0, 0x18, 0x17, 0x16, 0x15, 0x14, 0x13, 0x12, 0x11};
  // Independently: libsodium's combined decryption with that nonce and the envelope as associated
  // data.
  Bytes plain(body.size());
  unsigned long long plain_size = 0;
  ASSERT_EQ(
      crypto_aead_xchacha20poly1305_ietf_decrypt(
          plain.data(), &plain_size, nullptr, message.data() + kEnvelopeBytes,
          body.size() + kTagBytes, message.data(), kEnvelopeBytes, nonce.data(), key.bytes.data()),
      0);
  EXPECT_EQ(plain, body);

  Bytes scratch(body.size());
  const auto opened = open_sealed(message, kEnvelopeBytes, make_nonce(Channel::datagram, envelope),
                                  key, true, scratch);
  ASSERT_TRUE(opened);
  EXPECT_TRUE(std::equal(opened->begin(), opened->end(), body.begin(), body.end()));
  // Another key, channel, or any byte flipped: refused.
  EXPECT_FALSE(open_sealed(message, kEnvelopeBytes, make_nonce(Channel::datagram, envelope),
                           key_of(4), true, scratch));
  EXPECT_FALSE(open_sealed(message, kEnvelopeBytes, make_nonce(Channel::frame, envelope), key, true,
                           scratch));
  for (std::size_t i = 0; i < message.size(); ++i) {
    Bytes flipped = message;
    flipped[i] ^= 0x04;
    EXPECT_FALSE(open_sealed(flipped, kEnvelopeBytes, make_nonce(Channel::datagram, envelope), key,
                             true, scratch))
        << i;
  }
}

TEST(WireAead, InClearTheBodyIsReadableAndStillAuthenticated) {
  const TrafficKey key = key_of(3);
  const Envelope envelope{kProtocolVersion, 0, 1, kSalt, 9};
  const Bytes body = {9, 8, 7, 6};
  Bytes message(kEnvelopeBytes + body.size() + kTagBytes);
  write_envelope(envelope, message.data());
  std::copy(body.begin(), body.end(), message.begin() + kEnvelopeBytes);
  seal_in_place(message, kEnvelopeBytes, make_nonce(Channel::datagram, envelope), key, false);
  EXPECT_TRUE(std::equal(body.begin(), body.end(), message.begin() + kEnvelopeBytes));
  const Nonce nonce = make_nonce(Channel::datagram, envelope);
  // The tag is the AEAD's over an empty message with everything before it as associated data.
  EXPECT_EQ(crypto_aead_xchacha20poly1305_ietf_decrypt_detached(
                nullptr, nullptr, message.data(), 0, message.data() + message.size() - kTagBytes,
                message.data(), message.size() - kTagBytes, nonce.data(), key.bytes.data()),
            0);
  ASSERT_TRUE(open_sealed(message, kEnvelopeBytes, nonce, key, false, {}));
  Bytes changed = message;
  changed[kEnvelopeBytes] ^= 1;
  EXPECT_FALSE(open_sealed(changed, kEnvelopeBytes, nonce, key, false, {}));
}

TEST(WireAead, EverySealerDrawsItsOwnSalt) {
  std::set<std::uint64_t> salts;
  for (int i = 0; i < 1000; ++i) salts.insert(DatagramSealer(key_of(1), kSession, 1).salt());
  EXPECT_EQ(salts.size(), 1000u);
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
  window.start_after(40);  // a sender that said its last was 40
  for (std::uint64_t old : {0, 1, 39, 40}) EXPECT_FALSE(window.fresh(old)) << old;
  EXPECT_TRUE(window.accept(42));
  EXPECT_TRUE(window.accept(41));
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

Datagram tool_datagram(std::uint64_t sequence, std::uint32_t sender = 1,
                       std::uint64_t session = kSession) {
  Datagram d;
  Header* h = d.mutable_header();
  h->set_protocol_version(kProtocolVersion);
  h->set_session(session);
  h->set_sender(sender);
  h->set_sequence(sequence);
  h->set_sender_time_ns(123456789);
  ToolSample* tool = d.mutable_tool();
  tool->set_user(sender - 1);
  tool->set_sample_time_ns(42);
  tool->mutable_position()->set_x(0.01);
  tool->mutable_position()->set_y(-0.02);
  tool->mutable_position()->set_z(-0.003);
  tool->set_valid(true);
  tool->set_buttons(5);
  return d;
}

// Arbitrary body bytes sealed behind `envelope`, as a datagram or (with a length) a frame.
Bytes sealed(const Bytes& body, const Envelope& envelope, const TrafficKey& key,
             Channel channel = Channel::datagram) {
  const std::size_t clear = channel == Channel::frame ? kFrameClearBytes : kEnvelopeBytes;
  Bytes out(clear + body.size() + kTagBytes);
  if (channel == Channel::frame) write_le(body.size(), kFrameLengthBytes, out.data());
  write_envelope(envelope, out.data() + clear - kEnvelopeBytes);
  std::copy(body.begin(), body.end(), out.begin() + static_cast<long>(clear));
  seal_in_place(out, clear, make_nonce(channel, envelope), key, envelope.encrypted());
  return out;
}

// Two users: slot 0 (sender 1) and slot 1 (sender 2), each with its own key and sealer.
struct InspectorRig {
  SessionKey session = development_key();
  TrafficKey key = participant_key(session, 0), key2 = participant_key(session, 1);
  DatagramInspector inspector{kSession};
  InspectorRig() {
    inspector.allow_sender(1, key, kSalt);
    inspector.allow_sender(2, key2, kSalt + 1);
  }
  Bytes encode(const Datagram& d) const {
    return encode_datagram(
        d, {d.header().sender() == 2 ? key2 : key, d.header().sender() == 2 ? kSalt + 1 : kSalt});
  }
};

// Inspects `bytes` and checks that exactly the counter of `expected` (or accepted) rose by one.
void expect_outcome(DatagramInspector& inspector, const Bytes& bytes,
                    std::optional<Rejection> expected, const std::string& what) {
  const std::map<std::string, std::uint64_t> before = inspector.counters().snapshot();
  const std::optional<Datagram> result = inspector.inspect(bytes);
  const std::map<std::string, std::uint64_t> after = inspector.counters().snapshot();
  const std::string expected_name = expected ? std::string(to_string(*expected)) : "accepted";
  EXPECT_EQ(result.has_value(), !expected) << what;
  EXPECT_EQ(inspector.last_rejection(), expected) << what;
  ASSERT_EQ(before.size(), kRejectionCount + 1);
  for (const auto& [name, count] : after)
    EXPECT_EQ(count - before.at(name), name == expected_name ? 1u : 0u)
        << what << ": counter " << name;
}

TEST(WireDatagram, RoundTripsEveryBodyBehindTheDocumentedEnvelope) {
  const TrafficKey key = key_of(1);
  Datagram tool = tool_datagram(7);
  const Bytes bytes = encode_datagram(tool, {key, kSalt});
  EXPECT_EQ(bytes.size(), kEnvelopeBytes + tool.ByteSizeLong() + kTagBytes);
  const Envelope envelope = *read_envelope(bytes);
  EXPECT_EQ(envelope.version, kProtocolVersion);
  EXPECT_TRUE(envelope.encrypted());
  EXPECT_EQ(envelope.sender, 1u);
  EXPECT_EQ(envelope.salt, kSalt);
  EXPECT_EQ(envelope.sequence, 7u);
  auto decoded = decode_datagram(bytes, key, kSession);
  ASSERT_TRUE(std::holds_alternative<Datagram>(decoded));
  const Datagram& d = std::get<Datagram>(decoded);
  EXPECT_EQ(d.header().sequence(), 7u);
  EXPECT_EQ(d.header().sender_time_ns(), 123456789);
  EXPECT_EQ(d.tool().position().y(), -0.02);
  EXPECT_EQ(d.tool().sample_time_ns(), 42);
  EXPECT_EQ(d.tool().buttons(), 5u);
  EXPECT_TRUE(d.tool().valid());

  Datagram force;
  *force.mutable_header() = tool.header();
  force.mutable_force()->set_user(1);
  to_wire(Eigen::Vector3d(0.5, -1.25, 3.0), force.mutable_force()->mutable_force());
  force.mutable_force()->set_ir_epoch(12);
  force.mutable_force()->set_flags(3);
  decoded = decode_datagram(encode_datagram(force, {key, kSalt}), key);
  ASSERT_TRUE(std::holds_alternative<Datagram>(decoded));
  EXPECT_EQ(from_wire(std::get<Datagram>(decoded).force().force()),
            Eigen::Vector3d(0.5, -1.25, 3.0));
  EXPECT_EQ(std::get<Datagram>(decoded).force().ir_epoch(), 12u);

  Datagram pong;
  *pong.mutable_header() = tool.header();
  pong.mutable_pong()->set_client_send_ns(1);
  pong.mutable_pong()->set_server_receive_ns(kMaxClockNs - 1);
  pong.mutable_pong()->set_server_send_ns(0);
  decoded = decode_datagram(encode_datagram(pong, {key, kSalt}), key);
  ASSERT_TRUE(std::holds_alternative<Datagram>(decoded));
  EXPECT_EQ(std::get<Datagram>(decoded).pong().server_receive_ns(), kMaxClockNs - 1);

  // The in-place encoder produces the same bytes.
  Bytes reused;
  encode_datagram(tool, {key, kSalt}, reused);
  EXPECT_EQ(reused, bytes);

  // In clear: the serialized message lies readable behind the envelope, and decodes only
  // where clear datagrams are allowed.
  const Bytes clear = encode_datagram(tool, {key, kSalt, false});
  const std::string serialized = tool.SerializeAsString();
  EXPECT_EQ(std::memcmp(serialized.data(), clear.data() + kEnvelopeBytes, serialized.size()), 0);
  EXPECT_EQ(std::get<Rejection>(decode_datagram(clear, key)), Rejection::cleartext);
  EXPECT_TRUE(std::holds_alternative<Datagram>(decode_datagram(clear, key, kSession, true)));
}

TEST(WireDatagram, EncoderRefusesOversizedDatagrams) {
  Datagram d = tool_datagram(1);
  Datagram big;
  *big.mutable_header() = d.header();
  big.mutable_pong();
  // Unknown fields are kept and counted: grow the message past the limit with one.
  big.mutable_pong()
      ->GetReflection()
      ->MutableUnknownFields(big.mutable_pong())
      ->AddLengthDelimited(99, std::string(1400, 'x'));
  EXPECT_THROW(encode_datagram(big, {key_of(1), kSalt}), cohaptic::Error);
}

TEST(WireDatagramInspector, AcceptsValidDatagramsAndCountsThem) {
  InspectorRig rig;
  expect_outcome(rig.inspector, rig.encode(tool_datagram(1)), std::nullopt, "first");
  expect_outcome(rig.inspector, rig.encode(tool_datagram(2)), std::nullopt, "second");
  expect_outcome(rig.inspector, rig.encode(tool_datagram(1, 2)), std::nullopt, "other sender");
  EXPECT_EQ(rig.inspector.counters().accepted(), 3u);
  EXPECT_EQ(rig.inspector.counters().rejected(), 0u);
  const auto snapshot = rig.inspector.counters().snapshot();
  for (Rejection r : kAllRejections) EXPECT_EQ(snapshot.at(std::string(to_string(r))), 0u);
  EXPECT_EQ(snapshot.at("accepted"), 3u);
}

TEST(WireDatagramInspector, RejectsEachHostileDatagramForItsReason) {
  InspectorRig rig;
  const Datagram ten = tool_datagram(10);
  const Bytes valid = rig.encode(ten);
  const std::string serialized = ten.SerializeAsString();
  const Bytes body(serialized.begin(), serialized.end());
  const Envelope envelope{kProtocolVersion, kEncryptedFlag, 1, kSalt, 10};

  // Identity: another key, and slot 1's own key claiming slot 0.
  expect_outcome(rig.inspector, encode_datagram(ten, {key_of(2), kSalt}), Rejection::bad_tag,
                 "wrong key");
  expect_outcome(rig.inspector, encode_datagram(ten, {rig.key2, kSalt}), Rejection::bad_tag,
                 "slot 1's key, slot 0's name");
  for (std::size_t i :
       {std::size_t{0} + 2, std::size_t{6}, std::size_t{14}, valid.size() / 2, valid.size() - 1}) {
    Bytes flipped = valid;
    flipped[i] ^= 0x20;
    const Rejection expected =
        i == 2 ? Rejection::unknown_sender : Rejection::bad_tag;  // byte 2: the sender's name
    expect_outcome(rig.inspector, flipped, expected, fmt::format("flipped byte {}", i));
  }
  // Size.
  for (std::size_t length : {std::size_t{0}, std::size_t{1}, kDatagramOverheadBytes - 1})
    expect_outcome(rig.inspector, Bytes(valid.begin(), valid.begin() + static_cast<long>(length)),
                   Rejection::truncated, fmt::format("truncated to {}", length));
  for (std::size_t length :
       {kDatagramOverheadBytes, valid.size() - 1})  // the tag no longer where it was
    expect_outcome(rig.inspector, Bytes(valid.begin(), valid.begin() + static_cast<long>(length)),
                   Rejection::bad_tag, fmt::format("cut to {}", length));
  Bytes oversized = valid;
  oversized.resize(kMaxDatagramBytes + 1, 0);
  expect_outcome(rig.inspector, oversized, Rejection::oversized, "oversized");
  expect_outcome(
      rig.inspector,
      sealed(Bytes(kMaxDatagramBytes - kDatagramOverheadBytes + 1, 0), envelope, rig.key),
      Rejection::oversized, "oversized with a valid tag");
  // Versions and flags: a protocol 1 or 2 datagram starts with its protobuf (0x0a), not an
  // envelope.
  Bytes v1 = body;
  v1.resize(v1.size() + 32, 0xab);
  expect_outcome(rig.inspector, v1, Rejection::bad_version, "protocol 1 or 2");
  Envelope newer = envelope;
  newer.version = kProtocolVersion + 1;
  expect_outcome(rig.inspector, sealed(body, newer, rig.key), Rejection::bad_version,
                 "a newer envelope version");
  Envelope flagged = envelope;
  flagged.flags |= 0x80;
  expect_outcome(rig.inspector, sealed(body, flagged, rig.key), Rejection::bad_version,
                 "unknown flag");
  Datagram version = tool_datagram(11);
  version.mutable_header()->set_protocol_version(kProtocolVersion -
                                                 1);  // an older peer, in a new envelope
  expect_outcome(rig.inspector, rig.encode(version), Rejection::bad_version,
                 "an older sealed header version");
  // In clear, where encryption is required.
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(11), {rig.key, kSalt, false}),
                 Rejection::cleartext, "clear");
  // Authentic bytes that are not a Datagram (field 1 with the invalid wire type 7), or cut inside a
  // field.
  expect_outcome(rig.inspector, sealed(Bytes{0x0f, 0x01, 0x02}, envelope, rig.key),
                 Rejection::truncated, "unparsable");
  expect_outcome(rig.inspector, sealed(Bytes(body.begin(), body.end() - 3), envelope, rig.key),
                 Rejection::truncated, "body cut inside a field");
  // The sealed header must name the envelope's sender and sequence.
  Envelope other_sequence = envelope;
  other_sequence.sequence = 11;
  expect_outcome(rig.inspector, sealed(body, other_sequence, rig.key), Rejection::bad_tag,
                 "sequence disagrees");
  const std::string from_two = tool_datagram(10, 2).SerializeAsString();
  expect_outcome(rig.inspector, sealed(Bytes(from_two.begin(), from_two.end()), envelope, rig.key),
                 Rejection::bad_tag, "sender disagrees");
  expect_outcome(rig.inspector, rig.encode(tool_datagram(11, 1, kSession + 1)),
                 Rejection::wrong_session, "wrong session");
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(11, 7), {rig.key, kSalt}),
                 Rejection::unknown_sender, "unknown sender");
  // Authentic, but sealed by another sealer than the one the sender announced (a restarted peer's
  // old traffic).
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(11), {rig.key, kSalt + 9}),
                 Rejection::replayed, "other salt");

  Datagram nan = tool_datagram(12);
  nan.mutable_tool()->mutable_position()->set_y(std::numeric_limits<double>::quiet_NaN());
  expect_outcome(rig.inspector, rig.encode(nan), Rejection::non_finite, "NaN tool position");
  Datagram invalid_nan = nan;
  invalid_nan.mutable_tool()->set_valid(false);
  expect_outcome(rig.inspector, rig.encode(invalid_nan), Rejection::non_finite,
                 "NaN in an invalid sample");
  Datagram inf;
  *inf.mutable_header() = tool_datagram(13).header();
  to_wire(Eigen::Vector3d(0, std::numeric_limits<double>::infinity(), 0),
          inf.mutable_force()->mutable_force());
  expect_outcome(rig.inspector, rig.encode(inf), Rejection::non_finite, "infinite force");

  Datagram empty = tool_datagram(14);
  empty.clear_body();
  expect_outcome(rig.inspector, rig.encode(empty), Rejection::empty, "no body");

  // Clock readings outside [0, 2^61) ns: a pong's INT64_MIN would overflow the client's
  // clock offset arithmetic (undefined behaviour).
  constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min(),
                         kMax = std::numeric_limits<std::int64_t>::max();
  Datagram early = tool_datagram(15);
  early.mutable_header()->set_sender_time_ns(-1);
  expect_outcome(rig.inspector, rig.encode(early), Rejection::bad_time, "negative sender time");
  Datagram sample = tool_datagram(15);
  sample.mutable_tool()->set_sample_time_ns(kMaxClockNs);
  expect_outcome(rig.inspector, rig.encode(sample), Rejection::bad_time, "sample time at 2^61");
  Datagram ping;
  *ping.mutable_header() = tool_datagram(15).header();
  ping.mutable_ping()->set_client_send_ns(kMin);
  expect_outcome(rig.inspector, rig.encode(ping), Rejection::bad_time, "ping at INT64_MIN");
  for (int field = 0; field < 3; ++field) {
    Datagram pong;
    *pong.mutable_header() = tool_datagram(15).header();
    pong.mutable_pong()->set_client_send_ns(field == 0 ? kMin : 1);
    pong.mutable_pong()->set_server_receive_ns(field == 1 ? kMax : 2);
    pong.mutable_pong()->set_server_send_ns(field == 2 ? -3 : 3);
    expect_outcome(rig.inspector, rig.encode(pong), Rejection::bad_time,
                   "pong field " + std::to_string(field));
  }
  Datagram answer;
  *answer.mutable_header() = tool_datagram(15).header();
  answer.mutable_force()->set_tool_time_ns(kMax);
  expect_outcome(rig.inspector, rig.encode(answer), Rejection::bad_time,
                 "force answering INT64_MAX");

  // None of the rejected packets moved the window: the valid one is still fresh, once.
  expect_outcome(rig.inspector, valid, std::nullopt, "valid");
  expect_outcome(rig.inspector, valid, Rejection::replayed, "the same bytes again");
  expect_outcome(rig.inspector, rig.encode(tool_datagram(100)), std::nullopt, "jump to 100");
  expect_outcome(rig.inspector, rig.encode(tool_datagram(36)), Rejection::replayed,
                 "older than the window");
  expect_outcome(rig.inspector, rig.encode(tool_datagram(37)), std::nullopt,
                 "oldest in the window");
}

TEST(WireDatagramInspector, AcceptsReorderedFreshSequencesAndKeepsWindowsPerSender) {
  InspectorRig rig;
  for (std::uint64_t s : {20, 23, 21, 22, 5})
    expect_outcome(rig.inspector, rig.encode(tool_datagram(s)), std::nullopt,
                   fmt::format("sequence {}", s));
  expect_outcome(rig.inspector, rig.encode(tool_datagram(21)), Rejection::replayed, "21 again");
  // Sender 2 has its own window.
  expect_outcome(rig.inspector, rig.encode(tool_datagram(21, 2)), std::nullopt, "21 from sender 2");
  // A slot taken over by a new user (a new sealer, that said its last sequence was 3) starts
  // afresh.
  rig.inspector.allow_sender(1, rig.key, kSalt + 5, 3);
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(3), {rig.key, kSalt + 5}),
                 Rejection::replayed, "3: its last");
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(4), {rig.key, kSalt + 5}),
                 std::nullopt, "4: new user");
  expect_outcome(rig.inspector, rig.encode(tool_datagram(30)), Rejection::replayed,
                 "the old user's sealer");
  rig.inspector.forget_sender(2);
  EXPECT_FALSE(rig.inspector.allows(2));
  expect_outcome(rig.inspector, rig.encode(tool_datagram(22, 2)), Rejection::unknown_sender,
                 "forgotten");
}

TEST(WireDatagramInspector, RejectedPacketsNeverAdvanceTheWindow) {
  InspectorRig rig;
  expect_outcome(rig.inspector, rig.encode(tool_datagram(5)), std::nullopt, "5");
  Datagram far_nan = tool_datagram(1000);
  far_nan.mutable_tool()->mutable_position()->set_x(std::numeric_limits<double>::infinity());
  expect_outcome(rig.inspector, rig.encode(far_nan), Rejection::non_finite,
                 "authentic but infinite");
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(1000), {key_of(9), kSalt}),
                 Rejection::bad_tag, "forged");
  expect_outcome(rig.inspector, encode_datagram(tool_datagram(1000), {rig.key, kSalt + 1}),
                 Rejection::replayed, "other salt");
  EXPECT_EQ(*rig.inspector.window(1)->highest(), 5u);
  expect_outcome(rig.inspector, rig.encode(tool_datagram(6)), std::nullopt, "6 still fresh");
}

TEST(WireDatagramInspector, ExpectedSessionCanBeLearnedOrIgnored) {
  const TrafficKey key = key_of(1);
  DatagramInspector inspector;  // no session expected yet
  inspector.allow_sender(kServerSender, key, kSalt);
  expect_outcome(inspector, encode_datagram(tool_datagram(1, kServerSender, 77), {key, kSalt}),
                 std::nullopt, "any session");
  inspector.set_expected_session(78);
  expect_outcome(inspector, encode_datagram(tool_datagram(2, kServerSender, 77), {key, kSalt}),
                 Rejection::wrong_session, "77");
  expect_outcome(inspector, encode_datagram(tool_datagram(3, kServerSender, 78), {key, kSalt}),
                 std::nullopt, "78");
}

TEST(WireDatagramInspector, AcceptsDatagramsInClearOnlyWhereAllowed) {
  const TrafficKey key = key_of(1);
  DatagramInspector lenient(kSession, true);
  lenient.allow_sender(1, key, kSalt);
  expect_outcome(lenient, encode_datagram(tool_datagram(1), {key, kSalt, false}), std::nullopt,
                 "clear, allowed");
  expect_outcome(lenient, encode_datagram(tool_datagram(2), {key, kSalt, true}), std::nullopt,
                 "encrypted, always");
  Bytes tampered = encode_datagram(tool_datagram(3), {key, kSalt, false});
  tampered[kEnvelopeBytes + 5] ^= 1;  // readable, but not changeable
  expect_outcome(lenient, tampered, Rejection::bad_tag, "clear, tampered");
}

TEST(WireDatagramInspector, RandomBytesAndMutationsNeverThrowNorPassAsAuthentic) {
  InspectorRig rig;
  std::mt19937 rng(2024);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<std::size_t> length(0, 1500);
  for (int i = 0; i < 20000; ++i) {
    Bytes garbage(length(rng));
    for (auto& b : garbage) b = static_cast<std::uint8_t>(byte(rng));
    if (i % 2 && garbage.size() >=
                     kEnvelopeBytes) {  // half with a well-formed envelope naming an allowed sender
      write_envelope({kProtocolVersion, kEncryptedFlag, 1 + static_cast<std::uint32_t>(i % 4 == 1),
                      rng(), rng()},
                     garbage.data());
    }
    std::optional<Datagram> result;
    ASSERT_NO_THROW(result = rig.inspector.inspect(garbage));
    ASSERT_FALSE(result);
  }
  EXPECT_EQ(rig.inspector.counters().accepted(), 0u);
  EXPECT_EQ(rig.inspector.counters().rejected(), 20000u);
  EXPECT_GT(rig.inspector.counters().count(Rejection::bad_tag),
            4000u);  // the envelopes led as far as the tag

  const Bytes valid = rig.encode(tool_datagram(50));
  ASSERT_TRUE(rig.inspector.inspect(valid));
  int identical = 0;
  for (int i = 0; i < 20000; ++i) {
    Bytes m = valid;
    switch (rng() % 4) {
      case 0:  // flip one to four bits
        for (std::size_t k = 0, n = 1 + rng() % 4; k < n; ++k)
          m[rng() % m.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
        break;
      case 1:  // truncate
        m.resize(rng() % m.size());
        break;
      case 2:  // append
        for (std::size_t k = 0, n = 1 + rng() % 1400; k < n; ++k)
          m.push_back(static_cast<std::uint8_t>(byte(rng)));
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
      ASSERT_TRUE(r == Rejection::bad_tag || r == Rejection::truncated ||
                  r == Rejection::oversized || r == Rejection::bad_version ||
                  r == Rejection::cleartext || r == Rejection::unknown_sender)
          << "mutation " << i << ": " << to_string(r);
    }
  }
  EXPECT_EQ(rig.inspector.counters().accepted(), 1u);
  EXPECT_EQ(rig.inspector.counters().rejected(), 40000u);
  EXPECT_EQ(rig.inspector.counters().count(Rejection::replayed),
            static_cast<std::uint64_t>(identical));
}

TEST(WireDatagramInspector, AuthenticGarbageBodiesNeverThrow) {
  // A peer holding the key but sending nonsense: parse and every later check must hold.
  InspectorRig rig;
  std::mt19937 rng(7);
  const std::string valid = tool_datagram(1).SerializeAsString();
  for (int i = 0; i < 20000; ++i) {
    Bytes body(valid.begin(), valid.end());
    if (i % 2) {
      body.resize(rng() % 64);
      for (auto& b : body) b = static_cast<std::uint8_t>(rng());
    } else {
      for (int k = 0; k < 3; ++k) body[rng() % body.size()] = static_cast<std::uint8_t>(rng());
    }
    const Envelope envelope{kProtocolVersion, kEncryptedFlag, 1, kSalt,
                            1 + static_cast<std::uint64_t>(i)};
    ASSERT_NO_THROW(rig.inspector.inspect(sealed(body, envelope, rig.key)));
  }
  const RejectionCounters& c = rig.inspector.counters();
  EXPECT_EQ(c.accepted() + c.rejected(), 20000u);
}

TEST(WireDatagramInspector, RejectionNamesAreTheEnumerators) {
  std::set<std::string> names;
  for (Rejection r : kAllRejections) names.insert(std::string(to_string(r)));
  EXPECT_EQ(names,
            (std::set<std::string>{"oversized", "truncated", "bad_tag", "bad_version",
                                   "wrong_session", "unknown_sender", "replayed", "non_finite",
                                   "empty", "cleartext", "rate_limited", "bad_time"}));
}

// ---- TCP frames ----

Control control_with(std::uint64_t sequence, const std::string& text,
                     std::uint32_t sender = kServerSender) {
  Control c;
  Header* h = c.mutable_header();
  h->set_protocol_version(kProtocolVersion);
  h->set_session(kSession);
  h->set_sender(sender);
  h->set_sequence(sequence);
  c.mutable_event()->set_kind("test");
  c.mutable_event()->set_text(text);
  return c;
}

// A reader that opens the server's frames with `key`.
FrameReader reader_for(const TrafficKey& key, FrameReaderOptions options = {}) {
  return FrameReader(
      [key](std::uint32_t sender) { return sender == kServerSender ? &key : nullptr; }, options);
}

Bytes frame_of(const Control& c, const TrafficKey& key, std::uint64_t salt = kSalt,
               bool encrypt = true) {
  return encode_frame(c, {key, salt, encrypt});
}

// The error the reader throws once fed, and its reason.
std::pair<std::string, std::optional<Rejection>> frame_error(FrameReader& reader) {
  try {
    while (reader.next()) {
    }
  } catch (const FrameError& e) {
    return {e.what(), e.reason()};
  }
  return {"(no error)", std::nullopt};
}

TEST(WireFrame, LayoutIsLengthEnvelopeSealedBodyTag) {
  const TrafficKey key = key_of(5);
  const Control c = control_with(1, "hello");
  const Bytes frame = frame_of(c, key);
  const std::string body = c.SerializeAsString();
  ASSERT_EQ(frame.size(), 4 + kEnvelopeBytes + body.size() + kTagBytes);
  EXPECT_EQ(frame[0] | frame[1] << 8 | frame[2] << 16 | frame[3] << 24,
            static_cast<int>(body.size()));
  const Envelope envelope = *read_envelope(std::span(frame).subspan(4));
  EXPECT_EQ(envelope.sequence, 1u);
  EXPECT_EQ(envelope.sender, kServerSender);
  EXPECT_EQ(envelope.salt, kSalt);
  // Encrypted: the body is not readable; libsodium opens it with the length and envelope as
  // associated data.
  EXPECT_NE(Bytes(frame.begin() + kFrameClearBytes, frame.end() - kTagBytes),
            Bytes(body.begin(), body.end()));
  Bytes plain(body.size());
  const Nonce nonce = make_nonce(Channel::frame, envelope);
  ASSERT_EQ(
      crypto_aead_xchacha20poly1305_ietf_decrypt(
          plain.data(), nullptr, nullptr, frame.data() + kFrameClearBytes, body.size() + kTagBytes,
          frame.data(), kFrameClearBytes, nonce.data(), key.bytes.data()),
      0);
  EXPECT_EQ(plain, Bytes(body.begin(), body.end()));
}

TEST(WireFrame, ReaderReassemblesOneByteFeedsAndSeveralFramesPerFeed) {
  const TrafficKey key = key_of(5);
  Bytes stream;
  for (int i = 1; i <= 3; ++i) {
    const Bytes frame = frame_of(
        control_with(static_cast<std::uint64_t>(i),
                     std::string(100 * static_cast<std::size_t>(i), static_cast<char>('a' + i))),
        key);
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
  FrameReader slow = reader_for(key);
  std::vector<Control> received;
  for (std::uint8_t b : stream) {
    slow.feed(std::span(&b, 1));
    while (std::optional<Control> c = slow.next()) received.push_back(*c);
  }
  ASSERT_EQ(received.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(received[i].header().sequence(), static_cast<std::uint64_t>(i + 1));
    EXPECT_EQ(received[i].event().text(),
              std::string(100 * static_cast<std::size_t>(i + 1), static_cast<char>('a' + i + 1)));
  }
  EXPECT_EQ(slow.buffered(), 0u);

  FrameReader fast = reader_for(key);
  fast.feed(stream);
  for (int i = 1; i <= 3; ++i) {
    std::optional<Control> c = fast.next();
    ASSERT_TRUE(c);
    EXPECT_EQ(c->header().sequence(), static_cast<std::uint64_t>(i));
  }
  EXPECT_FALSE(fast.next());

  // Arbitrary chunking, with a partial frame left over.
  FrameReader chunked = reader_for(key);
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

TEST(WireFrame, TheClientsReaderTakesTheGreetingFirst) {
  const TrafficKey key = key_of(5);
  const Challenge challenge = random_challenge();
  const Bytes greeting = encode_greeting(challenge);
  ASSERT_EQ(greeting.size(), kGreetingBytes);
  EXPECT_EQ(std::string(greeting.begin(), greeting.begin() + 8), "cohaptic");
  EXPECT_EQ(greeting[8], kProtocolVersion);
  Bytes stream = greeting;
  const Bytes frame = frame_of(control_with(1, "after"), key);
  stream.insert(stream.end(), frame.begin(), frame.end());
  FrameReader reader = reader_for(key, {.expect_greeting = true});
  for (std::uint8_t b : stream) {  // byte by byte
    reader.feed(std::span(&b, 1));
    if (std::optional<Control> c = reader.next()) {
      if (c->has_hello()) {
        EXPECT_TRUE(is_challenge(c->hello().challenge(), challenge));
      } else {
        EXPECT_EQ(c->event().text(), "after");
      }
    }
  }
  EXPECT_FALSE(is_challenge(std::string(16, 'x'), challenge));

  // A peer of another version, or none at all.
  Bytes other_version = greeting;
  other_version[8] = 4;
  FrameReader newer = reader_for(key, {.expect_greeting = true});
  newer.feed(other_version);
  const auto [newer_error, newer_reason] = frame_error(newer);
  EXPECT_EQ(newer_reason, Rejection::bad_version);
  EXPECT_NE(newer_error.find("speaks protocol version 4, this program 3"), std::string::npos)
      << newer_error;
  FrameReader silent = reader_for(key, {.expect_greeting = true});
  silent.feed(frame);  // a server that sends a frame first is no cohaptic 3 server
  EXPECT_EQ(frame_error(silent).second, Rejection::bad_version);
  // The server's reader takes no greeting: one is garbage to it.
  FrameReader server = reader_for(key);
  server.feed(greeting);
  EXPECT_EQ(frame_error(server).second, Rejection::oversized);  // "coha" read as a length
}

TEST(WireFrame, ReaderCarriesAnIrAcrossTheStream) {
  const TrafficKey key = key_of(5);
  Control c = control_with(1, "");
  c.mutable_ir()->set_format_version(2);
  for (int i = 0; i < 100000; ++i) c.mutable_ir()->mutable_fem()->add_m_tilde_f64(i * 0.5);
  FrameReader reader = reader_for(key);
  reader.feed(frame_of(c, key));
  const std::optional<Control> received = reader.next();
  ASSERT_TRUE(received);
  ASSERT_EQ(received->ir().fem().m_tilde_f64_size(), 100000);
  EXPECT_EQ(received->ir().fem().m_tilde_f64(99999), 99999 * 0.5);
}

TEST(WireFrame, ReaderRejectsOversizedLengthBeforeReceivingTheBody) {
  FrameReader reader = reader_for(key_of(5), {.max_body_bytes = 1000});
  const Bytes length = {0xe9, 0x03, 0x00, 0x00};  // 1001
  reader.feed(length);
  const auto [error, reason] = frame_error(reader);
  EXPECT_EQ(reason, Rejection::oversized);
  EXPECT_NE(error.find("declared body length 1001 exceeds the limit of 1000"), std::string::npos)
      << error;
  // Sticky: the stream cannot be resynchronised.
  reader.feed(frame_of(control_with(1, "x"), key_of(5)));
  EXPECT_THROW(reader.next(), FrameError);

  FrameReader default_limit = reader_for(key_of(5));
  default_limit.feed(Bytes{0xff, 0xff, 0xff, 0xff});
  EXPECT_NE(frame_error(default_limit).first.find("exceeds the limit of 67108864"),
            std::string::npos);
}

TEST(WireFrame, ReaderRejectsEachHostileFrameForItsReason) {
  const TrafficKey key = key_of(5);
  const auto reason_of = [&](const Bytes& bytes, FrameReaderOptions options = {}) {
    FrameReader reader = reader_for(key, options);
    reader.feed(bytes);
    return frame_error(reader);
  };
  Bytes corrupted = frame_of(control_with(1, "hello"), key);
  corrupted[corrupted.size() - 1] ^= 0x80;
  const auto [corrupted_error, corrupted_reason] = reason_of(corrupted);
  EXPECT_EQ(corrupted_reason, Rejection::bad_tag);
  EXPECT_NE(corrupted_error.find("bad authentication tag"), std::string::npos) << corrupted_error;

  Bytes lengthened = frame_of(control_with(1, "hello"), key);
  lengthened.push_back(0);  // one more byte, and the length claims it: the tag no longer matches
  lengthened[0] = static_cast<std::uint8_t>(lengthened[0] + 1);
  EXPECT_EQ(reason_of(lengthened).second, Rejection::bad_tag);
  EXPECT_EQ(reason_of(frame_of(control_with(1, "hello"), key_of(6))).second,
            Rejection::bad_tag);  // wrong key
  EXPECT_EQ(reason_of(frame_of(control_with(1, "hello", 4), key)).second,
            Rejection::unknown_sender);
  EXPECT_EQ(reason_of(frame_of(control_with(1, "hello"), key, kSalt, false)).second,
            Rejection::cleartext);
  EXPECT_EQ(
      reason_of(frame_of(control_with(1, "hello"), key, kSalt, false), {.allow_cleartext = true})
          .second,
      std::nullopt);

  // A protocol 1 or 2 frame: [length][protobuf starting 0x0a][HMAC].
  const std::string v1_body = control_with(1, "old").SerializeAsString();
  Bytes v1(4, 0);
  write_le(v1_body.size(), 4, v1.data());
  v1.insert(v1.end(), v1_body.begin(), v1_body.end());
  v1.resize(v1.size() + 32, 0x55);
  const auto [v1_error, v1_reason] = reason_of(v1);
  EXPECT_EQ(v1_reason, Rejection::bad_version);
  EXPECT_NE(v1_error.find("envelope version byte 10"), std::string::npos) << v1_error;

  const Envelope envelope{kProtocolVersion, kEncryptedFlag, kServerSender, kSalt, 1};
  const auto [parse_error, parse_reason] =
      reason_of(sealed(Bytes{0x0f, 0x01, 0x02}, envelope, key, Channel::frame));
  EXPECT_EQ(parse_reason, Rejection::truncated);
  EXPECT_NE(parse_error.find("not a Control message"), std::string::npos) << parse_error;
  const std::string body = control_with(2, "x").SerializeAsString();
  EXPECT_EQ(
      reason_of(sealed(Bytes(body.begin(), body.end()), envelope, key, Channel::frame)).second,
      Rejection::bad_tag)
      << "sealed sequence 2, envelope 1";
  Control v1_header = control_with(1, "x");
  v1_header.mutable_header()->set_protocol_version(kProtocolVersion - 1);
  EXPECT_EQ(reason_of(frame_of(v1_header, key)).second, Rejection::bad_version);
  Control bodiless = control_with(1, "x");
  bodiless.clear_body();
  const auto [empty_error, empty_reason] = reason_of(frame_of(bodiless, key));
  EXPECT_EQ(empty_reason, Rejection::empty);
  EXPECT_NE(empty_error.find("without a body"), std::string::npos);
}

TEST(WireFrame, AStreamIsOneSealersStrictlyIncreasingSequence) {
  const TrafficKey key = key_of(5);
  FrameReader replay = reader_for(key);
  replay.feed(frame_of(control_with(4, "x"), key));
  replay.feed(frame_of(control_with(9, "x"), key));
  replay.feed(frame_of(control_with(9, "x"), key));
  EXPECT_TRUE(replay.next());
  EXPECT_TRUE(replay.next());
  const auto [error, reason] = frame_error(replay);
  EXPECT_EQ(reason, Rejection::replayed);
  EXPECT_NE(error.find("sequence 9 is not above the previous frame's 9"), std::string::npos)
      << error;

  // A frame of another connection's sealer, however new its sequence, is refused.
  FrameReader spliced = reader_for(key);
  spliced.feed(frame_of(control_with(1, "x"), key));
  spliced.feed(frame_of(control_with(100, "x"), key, kSalt + 1));
  EXPECT_TRUE(spliced.next());
  EXPECT_EQ(frame_error(spliced).second, Rejection::replayed);

  // The key may change within the stream (after a join), the sealer not.
  TrafficKey current = key_of(1);
  FrameReader rekeyed([&current](std::uint32_t) { return &current; });
  rekeyed.feed(frame_of(control_with(1, "x", kJoiningSender), key_of(1)));
  ASSERT_TRUE(rekeyed.next());
  EXPECT_EQ(rekeyed.last_sender(), kJoiningSender);
  current = key_of(2);
  rekeyed.feed(frame_of(control_with(2, "y", 3), key_of(2)));
  ASSERT_TRUE(rekeyed.next());
  EXPECT_EQ(rekeyed.last_sender(), 3u);
}

TEST(WireFrame, ReaderSurvivesRandomStreams) {
  const TrafficKey key = key_of(5);
  std::mt19937 rng(17);
  const Bytes valid = frame_of(control_with(1, "hello"), key);
  for (int i = 0; i < 2000; ++i) {
    FrameReader reader = reader_for(key, {.expect_greeting = i % 3 == 0, .max_body_bytes = 4096});
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
    Simulation simulation(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(2),
                          options);
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
  // An empty matrix's data() may be null, which memcmp must not be given even for 0 bytes.
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         (a.size() == 0 || std::memcmp(a.derived().data(), b.derived().data(),
                                       static_cast<std::size_t>(a.size()) * sizeof(double)) == 0);
}

bool bit_equal(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::memcmp(a.data(), b.data(), 3 * sizeof(double)) == 0;
}

void expect_same_ir(const cohaptic::IntermediateRepresentation& envelope_a,
                    const cohaptic::IntermediateRepresentation& envelope_b) {
  EXPECT_EQ(envelope_a.epoch, envelope_b.epoch);
  EXPECT_EQ(std::memcmp(&envelope_a.simulation_time, &envelope_b.simulation_time, sizeof(double)),
            0);
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
    for (int k = 0; k < 3; ++k)
      EXPECT_TRUE(bit_equal(a.patch[i].edge_normals[k], b.patch[i].edge_normals[k]));
  }
  EXPECT_TRUE(bit_equal(a.patch_vertex_normals, b.patch_vertex_normals));
  ASSERT_EQ(a.guard.size(), b.guard.size());
  for (std::size_t i = 0; i < a.guard.size(); ++i) {
    for (int k = 0; k < 3; ++k)
      EXPECT_TRUE(bit_equal(a.guard[i].corners[k], b.guard[i].corners[k]));
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
  EXPECT_TRUE(bit_equal(a.rest_forces, b.rest_forces));
}

// Through bytes, as it travels: to_wire, a Control frame, FrameReader, from_wire.
cohaptic::IntermediateRepresentation through_the_wire(
    const cohaptic::IntermediateRepresentation& ir) {
  const TrafficKey key = key_of(8);
  Control control;
  HeaderStamp(kSession, kServerSender).stamp(*control.mutable_header());
  to_wire(ir, control.mutable_ir());
  FrameReader reader = reader_for(key);
  reader.feed(frame_of(control, key));
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
  ir.force_limit = std::numeric_limits<double>::infinity();    // "no limit" travels too
  fem.m_tilde(0, 0) = std::nextafter(fem.m_tilde(0, 0), 0.0);  // a value float would not keep
  fem.rest_forces = Eigen::VectorXd::LinSpaced(fem.m_tilde.rows(), -0.1, 1.0 / 7.0);  // format 5
  const IntermediateRepresentation wire_ir = to_wire(ir);
  EXPECT_EQ(wire_ir.format_version(), 7u);
  EXPECT_EQ(wire_ir.fem().rest_forces_size(), fem.m_tilde.rows());
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
  EXPECT_TRUE(bit_equal(testing::evaluate_static(received, tool, remote).force,
                        testing::evaluate_static(original, tool, remote).force));
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
      {"fixed_axes length", [](auto& w) { w.mutable_fem()->mutable_fixed_axes()->pop_back(); },
       "fixed_axes bytes for"},
      {"fixed_axes mask", [](auto& w) { (*w.mutable_fem()->mutable_fixed_axes())[0] = 8; },
       "not a mask"},
      {"row count",
       [](auto& w) {
         w.mutable_fem()->set_row_node_count(
             static_cast<std::uint32_t>(w.fem().node_ids_size() + 1));
       },
       "exceeds the"},
      {"patch count",
       [](auto& w) { w.mutable_fem()->set_patch_node_count(w.fem().row_node_count() + 1); },
       "exceeds row_node_count"},
      {"rest positions", [](auto& w) { w.mutable_fem()->mutable_rest_positions()->RemoveLast(); },
       "rest_positions has"},
      {"NaN rest position", [nan](auto& w) { w.mutable_fem()->set_rest_positions(4, nan); },
       "rest_positions[4] is not finite"},
      {"empty patch", [](auto& w) { w.mutable_fem()->clear_patch(); }, "no triangle"},
      {"two-node triangle",
       [](auto& w) { w.mutable_fem()->mutable_patch(0)->mutable_nodes()->RemoveLast(); },
       "patch[0].nodes has 2 entries"},
      {"node outside patch",
       [](auto& w) { w.mutable_fem()->mutable_patch(0)->set_nodes(1, w.fem().patch_node_count()); },
       "outside the patch"},
      {"neighbour out of range",
       [](auto& w) { w.mutable_fem()->mutable_patch(0)->set_neighbours(2, w.fem().patch_size()); },
       "neighbours[2]"},
      {"neighbour below -1",
       [](auto& w) { w.mutable_fem()->mutable_patch(0)->set_neighbours(0, -2); },
       "neighbours[0] = -2"},
      {"two edge normals",
       [](auto& w) { w.mutable_fem()->mutable_patch(0)->mutable_edge_normals()->RemoveLast(); },
       "edge_normals has 2"},
      {"NaN normal",
       [nan](auto& w) { w.mutable_fem()->mutable_patch(0)->mutable_normal()->set_z(nan); },
       "patch[0].normal has a non-finite"},
      {"negative surface index",
       [](auto& w) { w.mutable_fem()->mutable_patch(0)->set_surface_index(-1); },
       "surface_index is negative"},
      {"vertex normals", [](auto& w) { w.mutable_fem()->add_patch_vertex_normals(0); },
       "patch_vertex_normals has"},
      {"guard corners", [](auto& w) { w.mutable_fem()->add_guard()->add_corners(); },
       "corners has 1 entries"},
      {"remote node",
       [](auto& w) { w.mutable_fem()->mutable_remotes(0)->set_nodes(0, w.fem().row_node_count()); },
       "outside the contact nodes"},
      {"remote vertex normals",
       [](auto& w) { w.mutable_fem()->mutable_remotes(0)->clear_vertex_normals(); },
       "vertex_normals has 0"},
      {"remote radius", [](auto& w) { w.mutable_fem()->mutable_remotes(0)->set_tool_radius(-1); },
       "tool_radius -1"},
      {"contact model",
       [](auto& w) {
         w.mutable_fem()->set_contact_model(static_cast<CondensedFem::ContactModel>(7));
       },
       "unknown contact model 7"},
      {"tool radius", [nan](auto& w) { w.set_tool_radius(nan); }, "tool_radius nan"},
      {"force limit", [](auto& w) { w.set_force_limit(-1); }, "force_limit -1"},
      {"simulation time",
       [](auto& w) { w.set_simulation_time(std::numeric_limits<double>::infinity()); },
       "simulation_time"},
      {"m_rows", [](auto& w) { w.mutable_fem()->set_m_rows(w.fem().m_rows() - 1); }, "m_rows"},
      {"m_cols", [](auto& w) { w.mutable_fem()->set_m_cols(w.fem().m_cols() + 3); }, "m_cols"},
      {"M~ length", [](auto& w) { w.mutable_fem()->mutable_m_tilde_f64()->RemoveLast(); },
       "M~ has"},
      {"NaN in M~", [nan](auto& w) { w.mutable_fem()->set_m_tilde_f64(5, nan); },
       "m_tilde_f64[5] is not finite"},
      {"u_B length", [](auto& w) { w.mutable_fem()->add_boundary_displacement_f64(0); },
       "u_B has 1 values, expected 0"},
      {"rest forces length", [](auto& w) { w.mutable_fem()->add_rest_forces(0); },
       "rest_forces has 1 values, expected m_rows"},
      {"NaN rest force",
       [nan](auto& w) {
         for (std::uint32_t i = 0; i < w.fem().m_rows(); ++i)
           w.mutable_fem()->add_rest_forces(i == 2 ? nan : 0.0);
       },
       "rest_forces[2] is not finite"},
      {"mixed precision", [](auto& w) { w.mutable_fem()->add_boundary_displacement_f32(0); },
       "mix f64 and f32"},
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
    for (std::size_t k = 0, n = 1 + rng() % 6; k < n; ++k)
      bytes[rng() % bytes.size()] = static_cast<char>(rng());
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
    const Eigen::Vector3d v(message.vertices(3 * i), message.vertices(3 * i + 1),
                            message.vertices(3 * i + 2));
    EXPECT_NEAR((v - centre).lpNorm<Eigen::Infinity>(), 0.065, 1e-12)
        << "vertex " << i << " is not on the cube's faces";
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
      p[k] = Eigen::Vector3d(message.vertices(3 * v), message.vertices(3 * v + 1),
                             message.vertices(3 * v + 2));
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
  EXPECT_NE(error_of([&] { from_wire(bad); }).find("triangle 3 refers to vertex 56"),
            std::string::npos);
  bad = message;
  bad.mutable_node_ids()->RemoveLast();
  EXPECT_NE(error_of([&] { from_wire(bad); }).find("55 node ids for 56 vertices"),
            std::string::npos);
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
