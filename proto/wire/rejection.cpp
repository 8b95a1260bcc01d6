#include "proto/wire/rejection.h"

namespace cohaptic::wire {

std::string_view to_string(Rejection reason) {
  switch (reason) {
    case Rejection::oversized:
      return "oversized";
    case Rejection::truncated:
      return "truncated";
    case Rejection::bad_tag:
      return "bad_tag";
    case Rejection::bad_version:
      return "bad_version";
    case Rejection::wrong_session:
      return "wrong_session";
    case Rejection::unknown_sender:
      return "unknown_sender";
    case Rejection::replayed:
      return "replayed";
    case Rejection::non_finite:
      return "non_finite";
    case Rejection::empty:
      return "empty";
    case Rejection::cleartext:
      return "cleartext";
    case Rejection::rate_limited:
      return "rate_limited";
    case Rejection::bad_time:
      return "bad_time";
  }
  return "unknown";
}

std::uint64_t RejectionCounters::rejected() const {
  std::uint64_t total = 0;
  for (Rejection reason : kAllRejections) total += count(reason);
  return total;
}

std::map<std::string, std::uint64_t> RejectionCounters::snapshot() const {
  std::map<std::string, std::uint64_t> counts;
  counts.emplace("accepted", accepted());
  for (Rejection reason : kAllRejections)
    counts.emplace(std::string(to_string(reason)), count(reason));
  return counts;
}

}  // namespace cohaptic::wire
