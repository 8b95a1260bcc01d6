#include "client/server_connection.h"

#include <spdlog/spdlog.h>

namespace cohaptic {

using asio::ip::tcp;

ServerConnection::ServerConnection(asio::io_context& io, std::string host, std::uint16_t port,
                                   const wire::SessionKey& key, Handlers handlers)
    : io_(io),
      host_(std::move(host)),
      port_(port),
      key_(key),
      handlers_(std::move(handlers)),
      sealer_(key, 0, 0),
      reconnect_timer_(io) {}

void ServerConnection::start() { connect(); }

void ServerConnection::connect() {
  if (stopped_) return;
  if (connection_) connection_->close();
  connection_.reset();
  std::error_code error;
  tcp::resolver resolver(io_);
  const auto endpoints = resolver.resolve(host_, std::to_string(port_), error);
  if (error) {
    spdlog::warn("cannot resolve {}: {}", host_, error.message());
    schedule_reconnect();
    return;
  }
  connecting_ = std::make_shared<tcp::socket>(io_);
  asio::async_connect(*connecting_, endpoints, [this, socket = connecting_](std::error_code e, const tcp::endpoint&) {
    if (socket != connecting_ || stopped_) return;  // superseded or stopped meanwhile
    connecting_.reset();
    if (e) {
      schedule_reconnect();
      return;
    }
    socket->set_option(tcp::no_delay(true));
    net::FramedConnection::Handlers handlers;
    handlers.on_control = [this](const wire::Control& control) { handlers_.on_control(control); };
    handlers.on_close = [this](net::CloseCause cause, const std::string& why) {
      switch (cause) {
        case net::CloseCause::peer_closed: drop("closed"); return;
        case net::CloseCause::rejected_frame:
          spdlog::error("control channel: {}", why);
          drop("protocol error");
          return;
        case net::CloseCause::io_error:
        case net::CloseCause::write_queue_full: drop(why); return;
      }
    };
    connection_ = net::FramedConnection::start(std::move(*socket), wire::FrameReader(key_), std::move(handlers));
    wire::Control join = handlers_.make_join();
    send(join);
  });
}

void ServerConnection::schedule_reconnect() {
  if (stopped_) return;
  reconnect_timer_.expires_after(kReconnectInterval);
  reconnect_timer_.async_wait([this](std::error_code e) {
    if (!e) connect();
  });
}

void ServerConnection::drop(const std::string& why) {
  if (stopped_) return;  // our own goodbye
  if (connection_) connection_->close();
  connection_.reset();
  handlers_.on_lost(why);
  schedule_reconnect();
}

void ServerConnection::send(wire::Control& control) {
  if (!connection_ || connection_->closed()) return;
  connection_->send(sealer_.seal(control), net::FrameKind::must_arrive);
}

void ServerConnection::stop() {
  stopped_ = true;
  reconnect_timer_.cancel();
}

asio::ip::address ServerConnection::server_address() const {
  return connection_ ? connection_->peer_address() : asio::ip::address();
}

}  // namespace cohaptic
