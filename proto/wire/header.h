// Header stamping: every Datagram and Control carries protocol version, session, sender,
// a per-channel sequence number and the sender's monotonic time (messages.proto, Header).
//
// One HeaderStamp per sending channel (e.g. the server's UDP socket, each TCP connection):
// its sequence starts at 1 and increases by one with every stamp, so receivers can drop
// duplicates and stale messages (a receiver's replay window treats 0 like any number).
// Times are the session clock's (common/util/monotonic_clock.h). stamp() is thread-safe.
#pragma once

#include <atomic>
#include <cstdint>

#include "cohaptic/messages.pb.h"

namespace cohaptic::wire {

/// 3: every frame and datagram sealed with its sender's traffic key (XChaCha20-Poly1305
/// behind a clear envelope); 2: IR format 2 (an envelope around a body), and like 1 the
/// shared session key's HMAC tag on clear messages.
constexpr std::uint32_t kProtocolVersion = 3;

/// Sender ids in Header.sender: 0 the server, k + 1 the user in slot k, kJoiningSender a
/// client that holds the session key and has no slot yet (its Join; traffic_keys.h).
constexpr std::uint32_t kServerSender = 0;
constexpr std::uint32_t kJoiningSender = 0xffff'ffff;
constexpr std::uint32_t sender_of_slot(std::uint32_t slot) { return slot + 1; }

class HeaderStamp {
 public:
  HeaderStamp(std::uint64_t session, std::uint32_t sender) : session_(session), sender_(sender) {}

  /// Fills `header`: version, session, sender, the next sequence number, now.
  void stamp(Header& header);
  /// A new header, as stamp() fills it.
  Header next();

  /// A client learns its session and slot from the server's Welcome.
  void set_session(std::uint64_t session) { session_.store(session, std::memory_order_relaxed); }
  void set_sender(std::uint32_t sender) { sender_.store(sender, std::memory_order_relaxed); }
  std::uint64_t session() const { return session_.load(std::memory_order_relaxed); }
  std::uint32_t sender() const { return sender_.load(std::memory_order_relaxed); }
  /// The sequence number the last stamp used (0 before the first).
  std::uint64_t last_sequence() const { return sequence_.load(std::memory_order_relaxed); }

 private:
  std::atomic<std::uint64_t> session_;
  std::atomic<std::uint32_t> sender_;
  std::atomic<std::uint64_t> sequence_{0};
};

}  // namespace cohaptic::wire
