#include "client/server_connection.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace cohaptic {

using asio::ip::tcp;

ServerConnection::ServerConnection(asio::io_context& io, std::string host, std::uint16_t port,
                                   wire::ClientKeys keys, bool encrypt, Handlers handlers)
    : io_(io),
      host_(std::move(host)),
      port_(port),
      keys_(std::move(keys)),
      encrypt_(encrypt),
      handlers_(std::move(handlers)),
      sealer_(0, 0, encrypt),
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
    failed_to_join(fmt::format("cannot resolve {}: {}", host_, error.message()));
    schedule_reconnect();
    return;
  }
  connecting_ = std::make_shared<tcp::socket>(io_);
  asio::async_connect(
      *connecting_, endpoints,
      [this, socket = connecting_](std::error_code e, const tcp::endpoint&) {
        if (socket != connecting_ || stopped_) return;  // superseded or stopped meanwhile
        connecting_.reset();
        if (e) {
          if (e == asio::error::connection_refused)
            failed_to_join(
                "connection refused: nothing listens there (is the server running, on this port?)");
          else if (e == asio::error::host_unreachable || e == asio::error::network_unreachable ||
                   e == asio::error::timed_out)
            failed_to_join(
                fmt::format("unreachable ({}): check the address and the network", e.message()));
          else
            failed_to_join(e.message());
          schedule_reconnect();
          return;
        }
        socket->set_option(tcp::no_delay(true));
        // Every connection starts over: the join key, until the Welcome names the slot.
        key_ = keys_.join_key();
        sealer_.set_key(key_);
        sealer_.stamp().set_sender(keys_.join_sender());
        join_sent_ = false;
        net::FramedConnection::Handlers handlers;
        handlers.on_control = [this](const wire::Control& control) { handle(control); };
        handlers.on_close = [this](net::CloseCause cause, const std::string& why) {
          switch (cause) {
            case net::CloseCause::peer_closed:
              if (join_sent_ && !welcomed_)
                failed_to_join(
                    "the server rejected the key: it closed the connection on our join (is it "
                    "using the same "
                    "--key-file?)");
              drop("closed");
              return;
            case net::CloseCause::rejected_frame:
              spdlog::error("control channel: {}", why);
              if (!welcomed_)
                failed_to_join(
                    "the server rejected the key: its frames do not authenticate with ours (is it "
                    "using the "
                    "same --key-file?)");
              drop("protocol error");
              return;
            case net::CloseCause::io_error:
            case net::CloseCause::write_queue_full:
            case net::CloseCause::write_stalled:
              drop(why);
              return;
          }
        };
        wire::FrameReader reader(
            [this](std::uint32_t sender) {
              return sender == wire::kServerSender ? &key_ : nullptr;
            },
            {.expect_greeting = true, .allow_cleartext = !encrypt_});
        connection_ = net::FramedConnection::start(std::move(*socket), std::move(reader),
                                                   std::move(handlers));
      });
}

void ServerConnection::handle(const wire::Control& control) {
  if (control.has_hello()) {
    greeted(control.hello());
  } else if (control.has_welcome()) {
    if (welcomed(control)) {
      welcomed_ = true;
      failed_to_join("");
      handlers_.on_control(control);
    }
  } else {
    handlers_.on_control(control);
  }
}

void ServerConnection::greeted(const wire::Hello& hello) {
  if (join_sent_) return;
  join_sent_ = true;
  client_challenge_ = wire::random_challenge();
  wire::Control join = handlers_.make_join();
  join.mutable_join()->set_challenge(hello.challenge());
  join.mutable_join()->set_client_challenge(client_challenge_.data(), client_challenge_.size());
  send(join);
}

// Checks the Welcome answers our join, then moves to the slot's key.
bool ServerConnection::welcomed(const wire::Control& control) {
  const wire::Welcome& welcome = control.welcome();
  if (!wire::is_challenge(welcome.client_challenge(), client_challenge_)) {
    spdlog::error(
        "control channel: a welcome that does not answer this connection's join (replayed?)");
    drop("protocol error");
    return false;
  }
  const std::optional<wire::TrafficKey> key = keys_.slot_key(welcome.slot());
  if (!key) {
    spdlog::error("the server gave slot {}, and the key file is another slot's", welcome.slot());
    drop("wrong slot");
    return false;
  }
  key_ = *key;
  sealer_.set_key(key_);
  sealer_.stamp().set_session(control.header().session());
  sealer_.stamp().set_sender(wire::sender_of_slot(welcome.slot()));
  return true;
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

void ServerConnection::failed_to_join(std::string why) {
  std::lock_guard lock(failure_mutex_);
  join_failure_ = std::move(why);
}

std::string ServerConnection::join_failure() const {
  std::lock_guard lock(failure_mutex_);
  return join_failure_;
}

void ServerConnection::stop() {
  stopped_ = true;
  reconnect_timer_.cancel();
}

asio::ip::address ServerConnection::server_address() const {
  return connection_ ? connection_->peer_address() : asio::ip::address();
}

}  // namespace cohaptic
