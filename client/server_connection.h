// ServerConnection: the client's control connection to the server, run by the I/O thread.
// It resolves the server's name and connects, sends the join its owner makes, and hands
// every verified Control to the owner. When a connection cannot be made, fails, or is
// dropped (the server said goodbye), it tries again every kReconnectInterval until stop();
// the owner hears of each loss of an open connection (on_lost). Meanwhile no IR or force
// arrives, so the haptic loop fades the force out.
// Its frames are sealed by one FrameSealer for the client's whole life, so their sequence
// numbers keep increasing across reconnections; each connection reads with a fresh
// FrameReader. Sockets are net::FramedConnection's.
#pragma once

#include <asio.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "cohaptic/messages.pb.h"
#include "net/framed_connection.h"
#include "proto/wire/sealer.h"
#include "proto/wire/session_key.h"

namespace cohaptic {

/// Wait between attempts to reach the server.
inline constexpr std::chrono::milliseconds kReconnectInterval{500};

class ServerConnection {
 public:
  struct Handlers {
    std::function<wire::Control()> make_join;                  ///< sent first on every connection
    std::function<void(const wire::Control&)> on_control;      ///< every verified frame
    std::function<void(const std::string& why)> on_lost;       ///< an open connection was lost
  };

  ServerConnection(asio::io_context& io, std::string host, std::uint16_t port, const wire::SessionKey& key,
                   Handlers handlers);

  /// Starts connecting (and reconnecting).
  void start();
  /// Sends `control` (stamped and sealed now) if connected; drops it otherwise.
  void send(wire::Control& control);
  /// Closes the connection and reconnects after kReconnectInterval (on_lost is called).
  void drop(const std::string& why);
  /// No more reconnects and no more on_lost; an open connection stays open for a last goodbye.
  void stop();

  /// The stamp of the frames sent: a client learns its session and sender from the Welcome.
  wire::HeaderStamp& stamp() { return sealer_.stamp(); }
  /// The server's address on the open connection.
  asio::ip::address server_address() const;

 private:
  void connect();
  void schedule_reconnect();

  asio::io_context& io_;
  std::string host_;
  std::uint16_t port_;
  wire::SessionKey key_;
  Handlers handlers_;
  wire::FrameSealer sealer_;
  asio::steady_timer reconnect_timer_;
  std::shared_ptr<asio::ip::tcp::socket> connecting_;  // the socket being connected
  std::shared_ptr<net::FramedConnection> connection_;
  bool stopped_ = false;
};

}  // namespace cohaptic
