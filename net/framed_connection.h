// FramedConnection: one TCP control connection carrying sealed frames
// (proto/wire/frame_codec.h), run by the thread of its socket's io_context.
//   - Reading: bytes arrive in a kReadBufferBytes buffer and are fed to the connection's
//     wire::FrameReader; each verified Control goes to on_control. A frame that fails its
//     checks closes the connection (on_close with CloseCause::rejected_frame): the stream
//     cannot be trusted any more.
//   - Writing: send() takes a sealed frame (wire::FrameSealer) into a BoundedWriteQueue,
//     written one at a time. When the queue is full the oldest superseded newest-wins frame
//     is dropped (see bounded_write_queue.h); if nothing can be dropped, the peer has
//     stopped reading and the connection closes (CloseCause::write_queue_full). A frame
//     that the kernel has not taken within the write timeout (its buffers are full: the
//     peer stopped reading, even if only newest-wins frames wait) closes it too
//     (CloseCause::write_stalled). So does a peer whose TCP has acknowledged nothing for
//     twice the write timeout while bytes the kernel took wait for it (the kernel's count
//     of unacknowledged bytes, polled): small frames fit in the kernel's buffers for
//     minutes, and a peer that stopped reading them would otherwise hold its slot as long.
//   - on_close is called once, on the I/O thread but never from inside send() or close(),
//     when the peer closes, an I/O error happens, a frame is rejected, the queue overflows
//     or a write stalls. close() by the owner calls nothing. After either, the handlers
//     are released, so they may capture the owner's per-connection state.
// It holds no keys and decides nothing about messages: the reader (with its key) is
// given, the frames come sealed, and what a message means is its owner's business.
// Held by shared_ptr: pending reads and writes keep it alive until they complete.
#pragma once

#include <array>
#include <asio.hpp>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "net/bounded_write_queue.h"
#include "proto/wire/frame_codec.h"

namespace cohaptic::net {

/// Bytes read from the socket at a time: frames larger than this arrive in several reads.
inline constexpr std::size_t kReadBufferBytes = 64 * 1024;
/// A frame not taken by the kernel within this time means the peer has stopped reading.
inline constexpr std::chrono::milliseconds kWriteTimeout{5000};

enum class CloseCause : std::uint8_t {
  peer_closed,
  io_error,
  rejected_frame,
  write_queue_full,
  write_stalled
};

class FramedConnection : public std::enable_shared_from_this<FramedConnection> {
 public:
  struct Handlers {
    std::function<void(const wire::Control&)> on_control;
    std::function<void(CloseCause cause, const std::string& why)> on_close;
  };
  enum class Sent : std::uint8_t { queued, queued_after_drop, closed };

  /// Takes over a connected socket and starts reading. Call on the I/O thread (or before it runs).
  static std::shared_ptr<FramedConnection> start(
      asio::ip::tcp::socket socket, wire::FrameReader reader, Handlers handlers,
      std::chrono::milliseconds write_timeout = kWriteTimeout);

  /// Queues a sealed frame; `closed` if the connection is (or, its queue overflowing, becomes)
  /// closed.
  Sent send(std::vector<std::uint8_t> frame, FrameKind kind);
  /// Closes the socket; pending operations end, no handler is called any more.
  void close();
  /// The largest frame body the peer may send from now on (a frame declaring more closes
  /// the connection as rejected: oversized). On the I/O thread.
  void set_max_frame_bytes(std::size_t bytes) { reader_.set_max_body_bytes(bytes); }

  bool closed() const { return closed_; }
  /// The peer as "address:port" (kept from the start: still known after closing).
  const std::string& peer() const { return peer_; }
  asio::ip::address peer_address() const { return peer_address_; }
  /// Why the reader rejected a frame, once it has (CloseCause::rejected_frame).
  std::optional<wire::Rejection> rejection() const { return rejection_; }
  /// Frames waiting behind the one being written (at most kMaxWaitingFrames).
  std::size_t frames_waiting() const { return queue_.waiting(); }
  /// Newest-wins frames dropped by the write queue.
  std::uint64_t frames_dropped() const { return queue_.dropped(); }

  class Passkey {  // only start() makes connections
    friend class FramedConnection;
    Passkey() = default;
  };
  FramedConnection(Passkey, asio::ip::tcp::socket socket, wire::FrameReader reader,
                   Handlers handlers, std::chrono::milliseconds write_timeout);

 private:
  void read_next();
  void write_next();
  /// Starts polling the kernel's unacknowledged bytes, if not already (after a write).
  void watch_delivery();
  void check_delivery();
  /// Closes and tells the owner (once), later on the I/O thread.
  void fail(CloseCause cause, std::string why);

  asio::ip::tcp::socket socket_;
  wire::FrameReader reader_;
  std::shared_ptr<const Handlers>
      handlers_;  // a handler running keeps them alive if it closes the connection
  BoundedWriteQueue queue_;
  asio::steady_timer write_timer_;  ///< runs while a write is in flight
  std::chrono::milliseconds write_timeout_;
  std::uint64_t writes_started_ = 0;
  asio::steady_timer
      delivery_timer_;  ///< runs while written bytes wait for the peer's acknowledgement
  std::uint64_t bytes_written_ = 0;                        ///< taken by the kernel, since the start
  std::uint64_t bytes_acknowledged_ = 0;                   ///< by the peer's TCP, as last polled
  std::chrono::steady_clock::time_point acknowledged_at_;  ///< when that count last grew
  bool watching_delivery_ = false;
  std::optional<wire::Rejection> rejection_;
  std::array<std::uint8_t, kReadBufferBytes> buffer_{};
  std::string peer_;
  asio::ip::address peer_address_;
  bool closed_ = false;
};

}  // namespace cohaptic::net
