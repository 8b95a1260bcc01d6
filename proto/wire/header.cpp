#include "proto/wire/header.h"

#include <chrono>

namespace cohaptic::wire {

std::int64_t monotonic_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void HeaderStamp::stamp(Header& header) {
  header.set_protocol_version(kProtocolVersion);
  header.set_session(session());
  header.set_sender(sender());
  header.set_sequence(sequence_.fetch_add(1, std::memory_order_relaxed) + 1);
  header.set_sender_time_ns(monotonic_now_ns());
}

Header HeaderStamp::next() {
  Header header;
  stamp(header);
  return header;
}

}  // namespace cohaptic::wire
