// BoundedWriteQueue: the frames waiting to be written to one stream socket, so that a
// peer that stops reading never makes its sender's memory grow without bound. No sockets
// and no threads: FramedConnection (or any later stream transport) drives it from its
// I/O thread, one frame in flight at a time.
//
// At most `max_waiting` frames (kMaxWaitingFrames by default) wait behind the one being
// written. Each frame is of one of two kinds:
//   - must_arrive: a welcome, an event, an error, a goodbye;
//   - newest_wins: a message that a newer one of its kind on the same connection makes
//     useless (an IR: a client only ever uses its newest).
// Policy when full: if a newest-wins frame is waiting and a newer newest-wins frame is
// waiting behind it or is the one pushed, the oldest such frame is dropped and counted,
// so the newest one always stays. Otherwise push() refuses the frame: the peer has
// stopped reading what must arrive, and the caller should close the connection. The frame
// being written is never dropped.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

namespace cohaptic::net {

enum class FrameKind : std::uint8_t { must_arrive, newest_wins };

/// Frames allowed to wait behind the one being written. A control connection carries a
/// few frames a second at most (IRs on a change of contact, events), so a peer with this
/// many waiting has stopped reading; with IRs of 10-400 kB that bounds a connection to 13 MB.
inline constexpr std::size_t kMaxWaitingFrames = 32;

class BoundedWriteQueue {
 public:
  enum class Push { queued, queued_after_drop, refused };

  explicit BoundedWriteQueue(std::size_t max_waiting = kMaxWaitingFrames);

  /// Queues `frame` behind the others, under the policy above.
  Push push(std::vector<std::uint8_t> frame, FrameKind kind);

  /// Takes the oldest waiting frame to be written and returns it (stable until
  /// end_write()); null if one is being written already or none waits.
  const std::vector<std::uint8_t>* begin_write();
  /// The frame being written is done (written, or abandoned).
  void end_write();

  bool writing() const { return writing_.has_value(); }
  std::size_t waiting() const { return waiting_.size(); }
  std::size_t max_waiting() const { return max_waiting_; }
  /// Newest-wins frames dropped because a newer one superseded them while the queue was full.
  std::uint64_t dropped() const { return dropped_; }

 private:
  struct Entry {
    std::vector<std::uint8_t> bytes;
    FrameKind kind = FrameKind::must_arrive;
  };
  std::size_t max_waiting_;
  std::deque<Entry> waiting_;
  std::optional<std::vector<std::uint8_t>> writing_;
  std::uint64_t dropped_ = 0;
};

}  // namespace cohaptic::net
