// LinkDelay: the fate of each message on a link with an injected shift delay: dropped, or
// delivered after a delay. Pure logic with a seeded generator, so studies are exact and
// repeatable; the server applies it with timers on its real sockets.
//
// Delay = constant + U(0, jitter); with probability `reorder` a message is held back by a
// further 2 x jitter + 1 ms, so it arrives after later ones; with probability `loss` it is
// dropped. An ordered link (TCP) never loses or reorders: each delivery time is strictly
// after the previous one's (net/delayed_delivery.h delivers at those absolute times).
// Units: ms in the settings, ns in the results.
#pragma once

#include <cstdint>
#include <optional>
#include <random>
#include <string>

namespace cohaptic {

struct LinkDelaySettings {
  double delay_ms = 0;
  double jitter_ms = 0;
  double loss = 0;     ///< probability in [0, 1)
  double reorder = 0;  ///< probability in [0, 1)
  std::uint64_t seed = 1;

  bool active() const { return delay_ms > 0 || jitter_ms > 0 || loss > 0 || reorder > 0; }
  std::string describe() const;
};

/// Throws Error naming the bad setting.
void validate(const LinkDelaySettings& settings);

struct LinkDelayCounters {
  std::uint64_t messages = 0, dropped = 0, reordered = 0;
  double delay_sum_ms = 0, delay_max_ms = 0;
};

class LinkDelay {
 public:
  LinkDelay(const LinkDelaySettings& settings, bool ordered);

  /// Delay for a message sent at `now_ns`, or nothing if it is lost. On an ordered link,
  /// now_ns + delay is strictly above every earlier message's.
  std::optional<std::int64_t> delay_ns(std::int64_t now_ns);

  /// Delay, jitter, loss and reorder from the next message on (a session switching
  /// conditions); the seeded stream, the order kept and the counters go on. Throws Error as
  /// validate() does.
  void set_settings(const LinkDelaySettings& settings);

  const LinkDelaySettings& settings() const { return settings_; }
  const LinkDelayCounters& counters() const { return counters_; }

 private:
  LinkDelaySettings settings_;
  bool ordered_;
  std::mt19937_64 rng_;
  std::int64_t last_delivery_ns_ = 0;
  bool delivered_before_ = false;
  LinkDelayCounters counters_;
};

}  // namespace cohaptic
