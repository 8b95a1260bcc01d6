// Delivery across a link with an injected shift delay (common/delay/link_delay.h): a
// message handed over now is delivered at once, after its delay by a timer on the I/O
// thread, or never (lost on the link). The caller keeps one LinkDelay per link and
// direction, and applies it where the message enters or leaves the process, so that the
// delay is the link's and nothing else's. Times: ns of monotonic_now_ns().
#pragma once

#include <asio.hpp>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>

#include "common/delay/link_delay.h"
#include "common/util/monotonic_clock.h"
#include "proto/wire/header.h"

namespace cohaptic::net {

/// Calls `deliver(delivered_ns)` after `link`'s delay for a message sent at `now_ns`:
/// inline on a link without injection, else from a timer on `io`'s thread that expires at
/// the absolute time now_ns + delay. Timers that are due fire in the order of their expiry,
/// so an ordered link's messages (strictly increasing times, link_delay.h) keep their
/// order, even a message of zero delay behind one whose timer has not run yet.
/// Returns false, without calling it, if the link loses the message.
template <class Deliver>
bool deliver_over(LinkDelay& link, asio::io_context& io, std::int64_t now_ns, Deliver deliver) {
  const std::optional<std::int64_t> delay = link.delay_ns(now_ns);
  if (!delay) return false;
  if (!link.settings().active()) {
    deliver(now_ns);
    return true;
  }
  auto timer = std::make_shared<asio::steady_timer>(
      io, std::chrono::steady_clock::time_point(std::chrono::nanoseconds(now_ns + *delay)));
  timer->async_wait([timer, deliver = std::move(deliver)](std::error_code error) mutable {
    if (!error) deliver(monotonic_now_ns());
  });
  return true;
}

}  // namespace cohaptic::net
