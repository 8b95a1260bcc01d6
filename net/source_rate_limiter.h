// SourceRateLimiter: how often datagrams that fail their checks may be inspected, so that a
// flood of hostile datagrams costs the receiver a table look-up each instead of a parse and
// an authentication. Two budgets, token buckets of failures (token_bucket.h):
//   - one per source address (not per port: changing port is free). A source new to the
//     table starts with first_burst tokens, not the full burst (unless proven, below), so
//     that rotating through many addresses buys little; one that keeps failing is heard
//     refill_per_s times a second.
//   - one for all sources together, all_sources_burst and all_sources_refill_per_s: past it
//     the datagrams of every source not yet proven are dropped unread, however many
//     addresses a flood comes from.
// A datagram from a limited source is dropped unread (the endpoint counts it as
// rate_limited). Valid datagrams spend nothing; a source that has sent one is proven
// (prove(): at most max_proven, the longest unheard replaced) and is limited by its own
// bucket only, so a flood from elsewhere never silences a peer that is known to be genuine.
// At most max_sources buckets are kept; a new source then replaces the one heard from
// longest ago. Times: ns of one monotonic clock. Not thread-safe: the I/O thread's.
#pragma once

#include <asio.hpp>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "net/token_bucket.h"

namespace cohaptic::net {

struct RateLimit {
  double burst = 64;         ///< failures a source may bank while quiet
  double first_burst = 4;    ///< failures a source new to the table may have before it is limited
  double refill_per_s = 16;  ///< failures a limited source may have per second
  double all_sources_burst = 256;         ///< failures of all unproven sources together, banked
  double all_sources_refill_per_s = 256;  ///< ... and per second
  std::size_t max_sources = 256;
  std::size_t max_proven = 16;
};

class SourceRateLimiter {
 public:
  explicit SourceRateLimiter(RateLimit limit = {});

  /// Whether a datagram from `source` is to be dropped unread now.
  bool limited(const asio::ip::address& source, std::int64_t now_ns);
  /// A datagram from `source` failed its checks: it takes a token from its source's budget
  /// and from the budget of all.
  void charge(const asio::ip::address& source, std::int64_t now_ns);
  /// A datagram from `source` passed its checks: the source is proven.
  void prove(const asio::ip::address& source, std::int64_t now_ns);

  std::size_t sources() const { return buckets_.size(); }

 private:
  struct Bucket {
    asio::ip::address source;
    TokenBucket tokens;
  };
  struct Proven {
    asio::ip::address source;
    std::int64_t heard_ns = 0;
  };
  Bucket* find(const asio::ip::address& source);
  bool proven(const asio::ip::address& source) const;

  RateLimit limit_;
  TokenBucket all_sources_;
  std::vector<Bucket> buckets_;  ///< a flat list: a handful of sources in practice
  std::vector<Proven> proven_;
};

}  // namespace cohaptic::net
