#include "net/source_rate_limiter.h"

#include <algorithm>

#include "common/util/error.h"

namespace cohaptic::net {

SourceRateLimiter::SourceRateLimiter(RateLimit limit) : limit_(limit) {
  if (!(limit.burst >= 1) || !(limit.refill_per_s > 0) || limit.max_sources == 0)
    throw Error("SourceRateLimiter: the burst must be at least 1, the refill positive, and one source tracked");
}

SourceRateLimiter::Bucket* SourceRateLimiter::find(const asio::ip::address& source) {
  for (Bucket& bucket : buckets_)
    if (bucket.source == source) return &bucket;
  return nullptr;
}

void SourceRateLimiter::refill(Bucket& bucket, std::int64_t now_ns) const {
  if (now_ns <= bucket.updated_ns) return;
  bucket.tokens = std::min(limit_.burst, bucket.tokens + static_cast<double>(now_ns - bucket.updated_ns) * 1e-9 * limit_.refill_per_s);
  bucket.updated_ns = now_ns;
}

bool SourceRateLimiter::limited(const asio::ip::address& source, std::int64_t now_ns) {
  Bucket* bucket = find(source);
  if (!bucket) return false;
  refill(*bucket, now_ns);
  return bucket->tokens < 1;
}

void SourceRateLimiter::charge(const asio::ip::address& source, std::int64_t now_ns) {
  Bucket* bucket = find(source);
  if (!bucket) {
    if (buckets_.size() < limit_.max_sources) {
      bucket = &buckets_.emplace_back();
    } else {
      bucket = &*std::min_element(buckets_.begin(), buckets_.end(),
                                  [](const Bucket& a, const Bucket& b) { return a.updated_ns < b.updated_ns; });
    }
    *bucket = Bucket{source, limit_.burst, now_ns};
  }
  refill(*bucket, now_ns);
  bucket->tokens = std::max(0.0, bucket->tokens - 1);
}

}  // namespace cohaptic::net
