// Sealer: the sending half of one channel's codec. Each outgoing message gets its header
// stamped (header.h: version, session, sender, the channel's next sequence number, the
// time) and is then sealed under the sender's traffic key (traffic_keys.h): a Control as a
// frame (frame_codec.h), a Datagram as a datagram (datagram_codec.h), encrypted unless
// made with encrypt = false.
//
// One sealer per sending channel (a TCP connection, a UDP socket, or the server's datagrams
// to one user), so that each channel's sequence numbers increase by one; each sealer draws
// a random salt when it is made, which keeps the AEAD's nonces unique across sealers and
// restarts (aead.h). The key may be given later (set_key: a client learns its slot's from
// the Welcome), and changed (the joining key, then the slot's) without a new salt or
// sequence. The receiving halves are FrameReader and DatagramInspector; with them the codec
// is the one place that holds keys: the sockets (net/) carry sealed bytes only. seal() is
// not thread-safe.
#pragma once

#include <cstdint>
#include <optional>
#include <type_traits>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "common/util/error.h"
#include "proto/wire/aead.h"
#include "proto/wire/datagram_codec.h"
#include "proto/wire/frame_codec.h"
#include "proto/wire/header.h"
#include "proto/wire/session_key.h"

namespace cohaptic::wire {

template <class Message>
class Sealer {
  static_assert(std::is_same_v<Message, Control> || std::is_same_v<Message, Datagram>);

 public:
  /// A sealer without a key yet: set_key() before the first seal().
  Sealer(std::uint64_t session, std::uint32_t sender, bool encrypt = true)
      : salt_(random_salt()), encrypt_(encrypt), stamp_(session, sender) {}
  Sealer(const TrafficKey& key, std::uint64_t session, std::uint32_t sender, bool encrypt = true)
      : Sealer(session, sender, encrypt) {
    key_ = key;
  }

  void set_key(const TrafficKey& key) { key_ = key; }
  bool has_key() const { return key_.has_value(); }

  /// Stamps `message`'s header, then returns its sealed bytes. Throws cohaptic::Error if
  /// the message is too large for its channel, or if there is no key yet.
  std::vector<std::uint8_t> seal(Message& message) {
    if (!key_) throw cohaptic::Error("a message to seal, and no key to seal it with yet");
    stamp_.stamp(*message.mutable_header());
    const SealWith with{*key_, salt_, encrypt_};
    if constexpr (std::is_same_v<Message, Control>)
      return encode_frame(message, with);
    else
      return encode_datagram(message, with);
  }

  /// This sealer's salt: a receiver accepts a sender's datagrams from its current sealer only.
  std::uint64_t salt() const { return salt_; }
  bool encrypts() const { return encrypt_; }
  /// The stamp, whose session and sender a client learns from the server's Welcome.
  HeaderStamp& stamp() { return stamp_; }
  const HeaderStamp& stamp() const { return stamp_; }

 private:
  std::optional<TrafficKey> key_;
  std::uint64_t salt_;
  bool encrypt_;
  HeaderStamp stamp_;
};

using FrameSealer = Sealer<Control>;
using DatagramSealer = Sealer<Datagram>;

}  // namespace cohaptic::wire
