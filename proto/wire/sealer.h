// Sealer: the sending half of one channel's codec. Each outgoing message gets its header
// stamped (header.h: version, session, sender, the channel's next sequence number, the
// time) and is then sealed with the session key: a Control as a tagged frame
// (frame_codec.h), a Datagram as a tagged datagram (datagram_codec.h).
//
// One sealer per sending channel (a TCP connection, a UDP socket), so that each channel's
// sequence numbers increase by one. The receiving halves are FrameReader and
// DatagramInspector. With these two halves the codec is the one place that holds keys and
// computes tags: the sockets (net/) carry sealed bytes only. seal() is not thread-safe.
#pragma once

#include <cstdint>
#include <type_traits>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "proto/wire/datagram_codec.h"
#include "proto/wire/frame_codec.h"
#include "proto/wire/header.h"
#include "proto/wire/session_key.h"

namespace cohaptic::wire {

template <class Message>
class Sealer {
  static_assert(std::is_same_v<Message, Control> || std::is_same_v<Message, Datagram>);

 public:
  Sealer(const SessionKey& key, std::uint64_t session, std::uint32_t sender) : key_(key), stamp_(session, sender) {}

  /// Stamps `message`'s header, then returns its sealed bytes. Throws cohaptic::Error if
  /// the message is too large for its channel.
  std::vector<std::uint8_t> seal(Message& message) {
    stamp_.stamp(*message.mutable_header());
    if constexpr (std::is_same_v<Message, Control>) return encode_frame(message, key_);
    else return encode_datagram(message, key_);
  }

  /// The stamp, whose session and sender a client learns from the server's Welcome.
  HeaderStamp& stamp() { return stamp_; }
  const HeaderStamp& stamp() const { return stamp_; }

 private:
  SessionKey key_;
  HeaderStamp stamp_;
};

using FrameSealer = Sealer<Control>;
using DatagramSealer = Sealer<Datagram>;

}  // namespace cohaptic::wire
