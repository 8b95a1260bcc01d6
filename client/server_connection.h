// ServerConnection: the client's control connection to the server, run by the I/O thread.
// It resolves the server's name and connects, waits for the server's greeting, sends the
// join its owner makes (adding the greeting's challenge and a challenge of its own), checks
// that the Welcome answers that join, and hands every verified Control to the owner. When
// a connection cannot be made, fails, or is dropped (the server said goodbye), it tries
// again every kReconnectInterval until stop(); the owner hears of each loss of an open
// connection (on_lost). Meanwhile no IR or force arrives, so the haptic loop fades the
// force out.
// Keys (wire/traffic_keys.h): each connection starts with the join key (the joining key
// with the session key, else the participant key), and moves to the slot's key once the
// Welcome names the slot; frames from the server are opened with the same key.
// Its frames are sealed by one FrameSealer for the client's whole life, so their sequence
// numbers keep increasing across reconnections; each connection reads with a fresh
// FrameReader. Sockets are net::FramedConnection's.
#pragma once

#include <asio.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "cohaptic/messages.pb.h"
#include "net/framed_connection.h"
#include "proto/wire/sealer.h"
#include "proto/wire/traffic_keys.h"

namespace cohaptic {

/// Wait between attempts to reach the server.
inline constexpr std::chrono::milliseconds kReconnectInterval{500};

class ServerConnection {
 public:
  struct Handlers {
    std::function<wire::Control()> make_join;  ///< sent on every connection, once greeted
    std::function<void(const wire::Control&)>
        on_control;  ///< every verified frame (a Welcome once checked)
    std::function<void(const std::string& why)> on_lost;  ///< an open connection was lost
  };

  /// `encrypt`: seal frames encrypted (else in clear, and accept the server's in clear).
  ServerConnection(asio::io_context& io, std::string host, std::uint16_t port,
                   wire::ClientKeys keys, bool encrypt, Handlers handlers);

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
  /// The key of the connection's traffic now: after the Welcome, the slot's.
  const wire::TrafficKey& key() const { return key_; }
  /// The server's address on the open connection.
  asio::ip::address server_address() const;
  /// Why no connection has been welcomed yet: "connection refused ...", "unreachable ...",
  /// "the server rejected the key ...", or empty when nothing failed (or one was welcomed).
  /// Any thread may read it.
  std::string join_failure() const;

 private:
  void failed_to_join(std::string why);
  void connect();
  void schedule_reconnect();
  void handle(const wire::Control& control);
  void greeted(const wire::Hello& hello);
  bool welcomed(const wire::Control& control);

  asio::io_context& io_;
  std::string host_;
  std::uint16_t port_;
  wire::ClientKeys keys_;
  bool encrypt_;
  Handlers handlers_;
  wire::FrameSealer sealer_;
  wire::TrafficKey key_;                ///< this connection's, for both directions
  wire::Challenge client_challenge_{};  ///< the one the Welcome must echo
  bool join_sent_ = false;
  asio::steady_timer reconnect_timer_;
  std::shared_ptr<asio::ip::tcp::socket> connecting_;  // the socket being connected
  std::shared_ptr<net::FramedConnection> connection_;
  bool stopped_ = false;
  bool welcomed_ = false;  // on some connection
  mutable std::mutex failure_mutex_;
  std::string join_failure_;  // guarded by failure_mutex_
};

}  // namespace cohaptic
