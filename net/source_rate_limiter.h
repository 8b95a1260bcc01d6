// SourceRateLimiter: how often each source address may send datagrams that fail their
// checks, so that a flood of hostile datagrams costs the receiver a table look-up each
// instead of a parse and an authentication. One token bucket per source address (not per
// port: changing port is free): every rejected datagram takes a token; a source with less
// than one token is limited, and its datagrams are dropped unread (the endpoint counts
// them as rate_limited) until the bucket refills. A source that keeps failing is thus heard
// at most refill_per_s times a second, after an initial burst.
// Sources that send valid datagrams spend nothing. At most max_sources are tracked; a new
// one then replaces the source heard from longest ago. Times: ns of one monotonic clock.
// Not thread-safe: the I/O thread's.
#pragma once

#include <asio.hpp>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace cohaptic::net {

struct RateLimit {
  double burst = 64;          ///< failures a source may have before it is limited
  double refill_per_s = 16;   ///< failures a limited source may have per second
  std::size_t max_sources = 256;
};

class SourceRateLimiter {
 public:
  explicit SourceRateLimiter(RateLimit limit = {});

  /// Whether a datagram from `source` is to be dropped unread now.
  bool limited(const asio::ip::address& source, std::int64_t now_ns);
  /// A datagram from `source` failed its checks: it takes a token.
  void charge(const asio::ip::address& source, std::int64_t now_ns);

  std::size_t sources() const { return buckets_.size(); }

 private:
  struct Bucket {
    asio::ip::address source;
    double tokens = 0;
    std::int64_t updated_ns = 0;
  };
  Bucket* find(const asio::ip::address& source);
  void refill(Bucket& bucket, std::int64_t now_ns) const;

  RateLimit limit_;
  std::vector<Bucket> buckets_;  ///< a flat list: a handful of sources in practice
};

}  // namespace cohaptic::net
