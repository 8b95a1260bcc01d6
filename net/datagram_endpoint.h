// DatagramEndpoint: one UDP socket and its receive loop, run by the thread of its
// io_context. Each packet received (into a kDatagramBufferBytes buffer, larger than any
// valid datagram, so that an oversized one is seen whole and rejected as such) goes
// through the endpoint's wire::DatagramInspector, which checks it and counts each
// rejection by reason; an accepted datagram goes to the handler with its sender's address
// and its arrival time. send() sends sealed bytes (wire::DatagramSealer) and counts them.
//
// Floods: a source address whose datagrams keep failing is rate limited
// (source_rate_limiter.h): its datagrams are then dropped unread and counted as
// rate_limited, so a flood costs a table look-up per datagram. The endpoints of the peers
// this side has admitted (trust(): a joined user's, the server's) are never limited, so a
// flood from their host never silences them. After each wake-up the socket is drained of
// what is already queued before waiting again, and its receive buffer is asked to be
// kReceiveBufferBytes, so that a burst does not overflow the kernel's queue; what the
// kernel still drops from a full queue is counted (kernel_dropped(): SO_RXQ_OVFL).
// It holds no keys and decides nothing about messages: the inspector (with its keys and
// allowed senders) is given, the datagrams come sealed. Counters: read them on the I/O
// thread, or after it stopped; the inspector's rejection counters from any thread.
#pragma once

#include <array>
#include <atomic>
#include <asio.hpp>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "net/source_rate_limiter.h"
#include "proto/wire/datagram_codec.h"

namespace cohaptic::net {

/// The receive buffer: every valid datagram (at most wire::kMaxDatagramBytes) fits with room to
/// spare.
inline constexpr std::size_t kDatagramBufferBytes = 2048;
static_assert(kDatagramBufferBytes > wire::kMaxDatagramBytes);
/// The socket's kernel receive queue asked for (the kernel caps it at net.core.rmem_max).
inline constexpr int kReceiveBufferBytes = 4 << 20;
/// Datagrams read per wake-up at most, before the loop goes back to the reactor.
inline constexpr int kReadsPerWakeUp = 64;

class DatagramEndpoint {
 public:
  using Handler = std::function<void(wire::Datagram&& datagram, const asio::ip::udp::endpoint& from,
                                     std::int64_t arrival_ns)>;

  /// Opens and binds the socket (port 0: any free port). Throws std::system_error if it cannot.
  DatagramEndpoint(asio::io_context& io, const asio::ip::udp::endpoint& local,
                   std::unique_ptr<wire::DatagramInspector> inspector, RateLimit limit = {});

  /// Starts the receive loop; it runs until close().
  void start(Handler on_datagram);
  /// Sends `datagram` (sealed bytes) to `to`, without waiting; a send error is not reported
  /// (UDP: the datagram is simply lost).
  void send(std::vector<std::uint8_t> datagram, const asio::ip::udp::endpoint& to);
  void close();

  /// Datagrams from `peer` (address and port) are never rate limited; distrust() undoes it.
  /// Its address is proven to the rate limiter from then on (source_rate_limiter.h).
  void trust(const asio::ip::udp::endpoint& peer);
  void distrust(const asio::ip::udp::endpoint& peer);

  std::uint16_t port() const { return port_; }
  wire::DatagramInspector& inspector() { return *inspector_; }
  const wire::DatagramInspector& inspector() const { return *inspector_; }
  /// Datagrams the kernel took (a send aborted by close() or failed is not counted).
  std::uint64_t sent() const { return sent_->load(std::memory_order_relaxed); }
  /// Datagrams the kernel dropped for this socket because its receive queue was full, as
  /// of the last datagram read (the kernel's count: it wraps at 2^32). From any thread.
  std::uint64_t kernel_dropped() const { return kernel_dropped_.load(std::memory_order_relaxed); }

 private:
  void receive_next();
  /// Reads one datagram if one is queued (false: none was).
  bool read_one();
  void take(std::size_t bytes);
  bool trusted(const asio::ip::udp::endpoint& peer) const;

  asio::ip::udp::socket socket_;
  std::unique_ptr<wire::DatagramInspector> inspector_;
  SourceRateLimiter limiter_;
  std::vector<asio::ip::udp::endpoint> trusted_;
  Handler on_datagram_;
  std::array<std::uint8_t, kDatagramBufferBytes> buffer_{};
  asio::ip::udp::endpoint from_;
  std::uint16_t port_ = 0;
  // Shared with pending sends' handlers, which may run after this endpoint is gone.
  std::shared_ptr<std::atomic<std::uint64_t>> sent_ =
      std::make_shared<std::atomic<std::uint64_t>>(0);
  std::atomic<std::uint64_t> kernel_dropped_{0};
};

}  // namespace cohaptic::net
