// ClockOffsetEstimator: the offset between a client's and the server's monotonic clocks,
// estimated NTP-style.
//
// A ping leaves the client at t0 (client clock), reaches the server at t1 and leaves at t2
// (server clock), and is back at t3 (client clock). Then
//   offset = ((t1 - t0) + (t2 - t3)) / 2   (server = client + offset)
//   round trip = (t3 - t0) - (t2 - t1).
// Of the last `window` samples, the one with the smallest round trip wins: its error is
// at most half its round trip, and queueing only ever adds to a round trip. Units: ns.
// Times must lie in [0, 2^61) ns (the wire rejects others as bad_time): then no offset,
// round trip or conversion overflows.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace cohaptic {

class ClockOffsetEstimator {
 public:
  explicit ClockOffsetEstimator(std::size_t window = 64);

  /// A completed ping. Samples with a negative round trip (clock errors) are ignored.
  void add(std::int64_t t0, std::int64_t t1, std::int64_t t2, std::int64_t t3);

  bool valid() const { return best_ >= 0; }
  std::int64_t offset_ns() const {
    return valid() ? samples_[static_cast<std::size_t>(best_)].offset : 0;
  }
  std::int64_t round_trip_ns() const {
    return valid() ? samples_[static_cast<std::size_t>(best_)].round_trip : 0;
  }
  std::int64_t to_server(std::int64_t client_ns) const { return client_ns + offset_ns(); }
  std::int64_t to_client(std::int64_t server_ns) const { return server_ns - offset_ns(); }

 private:
  struct Sample {
    std::int64_t offset = 0;
    std::int64_t round_trip = 0;
  };
  std::vector<Sample> samples_;  // ring of the last `window`
  std::size_t next_ = 0;
  std::size_t count_ = 0;
  long best_ = -1;
};

}  // namespace cohaptic
