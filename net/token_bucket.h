// TokenBucket: a rate limit as a value. It holds at most `capacity` tokens and gains
// `refill_per_s` a second up to that; each event allowed takes one. Over any window of T
// seconds it allows at most capacity + refill_per_s * T events. Times: ns of one
// monotonic clock, which must not go backwards (an earlier time refills nothing).
#pragma once

#include <algorithm>
#include <cstdint>

namespace cohaptic::net {

struct TokenBucket {
  double capacity = 1;
  double refill_per_s = 1;
  double tokens = 1;
  std::int64_t updated_ns = 0;

  void refill(std::int64_t now_ns) {
    if (now_ns <= updated_ns) return;
    tokens =
        std::min(capacity, tokens + static_cast<double>(now_ns - updated_ns) * 1e-9 * refill_per_s);
    updated_ns = now_ns;
  }
  /// Whether no event is allowed now.
  bool empty(std::int64_t now_ns) {
    refill(now_ns);
    return tokens < 1;
  }
  /// An event happened (allowed or not): it takes a token if one is left.
  void spend(std::int64_t now_ns) {
    refill(now_ns);
    tokens = std::max(0.0, tokens - 1);
  }
  /// Takes a token and returns true, or returns false if none is left.
  bool try_take(std::int64_t now_ns) {
    if (empty(now_ns)) return false;
    tokens -= 1;
    return true;
  }
};

}  // namespace cohaptic::net
