// Outbox: what one simulation step has to send, and to whom. The simulation thread fills
// one per step and hands it to the I/O thread in one piece (the only thing it posts
// there); ConnectionHandler::send() stamps, seals and sends each message to the user now
// in its slot (a slot left empty in the meantime gets nothing).
#pragma once

#include <optional>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "common/delay/link_delay.h"

namespace cohaptic {

template <class Message>
struct ToSlot {
  int slot = 0;
  Message message;
  /// An IR sent as compliance rows: the next one builds on it, so it is never dropped
  /// for a newer one (newest-wins applies to whole IRs only).
  bool must_arrive = false;
};

struct Outbox {
  /// The protocol served from this step on, told to every user before anything else of the
  /// outbox (a switched condition, served_conditions.h); unset: unchanged.
  std::optional<wire::Protocol> protocol_switch;
  /// The injected shift delay on every link from now on (a switched condition); unset: unchanged.
  std::optional<LinkDelaySettings> link_delay;
  std::vector<ToSlot<wire::Control>>
      irs;  ///< P1: new IRs, over TCP (newest wins unless must_arrive)
  std::vector<ToSlot<wire::Datagram>> datagrams;  ///< P1: IR keep-alives; P0: forces (UDP)

  bool empty() const { return !protocol_switch && !link_delay && irs.empty() && datagrams.empty(); }
};

}  // namespace cohaptic
