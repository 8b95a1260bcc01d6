#include "proto/wire/header.h"

#include "common/util/monotonic_clock.h"

namespace cohaptic::wire {

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
