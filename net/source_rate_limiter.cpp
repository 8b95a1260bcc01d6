#include "net/source_rate_limiter.h"

#include <algorithm>

#include "common/util/error.h"

namespace cohaptic::net {

SourceRateLimiter::SourceRateLimiter(RateLimit limit)
    : limit_(limit),
      all_sources_{limit.all_sources_burst, limit.all_sources_refill_per_s, limit.all_sources_burst,
                   0} {
  if (!(limit.burst >= 1) || !(limit.first_burst >= 1) || limit.first_burst > limit.burst ||
      !(limit.refill_per_s > 0) || !(limit.all_sources_burst >= 1) ||
      !(limit.all_sources_refill_per_s > 0) || limit.max_sources == 0 || limit.max_proven == 0)
    throw Error(
        "SourceRateLimiter: the bursts must be at least 1 (the first at most the burst), the "
        "refills "
        "positive, and one source tracked");
}

SourceRateLimiter::Bucket* SourceRateLimiter::find(const asio::ip::address& source) {
  for (Bucket& bucket : buckets_)
    if (bucket.source == source) return &bucket;
  return nullptr;
}

bool SourceRateLimiter::proven(const asio::ip::address& source) const {
  return std::any_of(proven_.begin(), proven_.end(),
                     [&](const Proven& p) { return p.source == source; });
}

bool SourceRateLimiter::limited(const asio::ip::address& source, std::int64_t now_ns) {
  if (!proven(source) && all_sources_.empty(now_ns)) return true;
  Bucket* bucket = find(source);
  return bucket && bucket->tokens.empty(now_ns);
}

void SourceRateLimiter::charge(const asio::ip::address& source, std::int64_t now_ns) {
  all_sources_.spend(now_ns);
  Bucket* bucket = find(source);
  if (!bucket) {
    if (buckets_.size() < limit_.max_sources) {
      bucket = &buckets_.emplace_back();
    } else {
      bucket = &*std::min_element(buckets_.begin(), buckets_.end(),
                                  [](const Bucket& a, const Bucket& b) {
                                    return a.tokens.updated_ns < b.tokens.updated_ns;
                                  });
    }
    const double tokens = proven(source) ? limit_.burst : limit_.first_burst;
    *bucket = Bucket{source, TokenBucket{limit_.burst, limit_.refill_per_s, tokens, now_ns}};
  }
  bucket->tokens.spend(now_ns);
}

void SourceRateLimiter::prove(const asio::ip::address& source, std::int64_t now_ns) {
  for (Proven& p : proven_)
    if (p.source == source) {
      p.heard_ns = now_ns;
      return;
    }
  if (proven_.size() < limit_.max_proven) {
    proven_.push_back({source, now_ns});
    return;
  }
  *std::min_element(proven_.begin(), proven_.end(), [](const Proven& a, const Proven& b) {
    return a.heard_ns < b.heard_ns;
  }) = {source, now_ns};
}

}  // namespace cohaptic::net
