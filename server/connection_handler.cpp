#include "server/connection_handler.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>

#include "common/net/link_delay.h"
#include "net/delayed_delivery.h"
#include "net/framed_connection.h"
#include "proto/wire/header.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic {

using asio::ip::tcp;
using asio::ip::udp;

// One control connection; a user once it has joined.
struct ConnectionHandler::Participant {
  std::shared_ptr<net::FramedConnection> connection;
  wire::FrameSealer sealer;  // this connection's frames
  int slot = -1;
  std::string user_name;
  udp::endpoint udp_endpoint;
  LinkDelay to_client_udp, to_client_tcp, from_client_udp;
  bool gone = false;
  Participant(const wire::SessionKey& key, std::uint64_t session, const LinkDelaySettings& shift)
      : sealer(key, session, wire::kServerSender),
        to_client_udp(shift, false),
        to_client_tcp(shift, true),
        from_client_udp(shift, false) {}
};

namespace {

std::unique_ptr<wire::DatagramInspector> server_inspector(const wire::SessionKey& key, std::uint64_t session) {
  return std::make_unique<wire::DatagramInspector>(key, session);
}

}  // namespace

ConnectionHandler::ConnectionHandler(asio::io_context& io, const ServeOptions& options, wire::Welcome welcome,
                                     const wire::SessionKey& key, std::uint64_t session, ToolInputs& tools,
                                     record::SessionRecorder* recorder)
    : io_(io),
      options_(options),
      welcome_(std::move(welcome)),
      key_(key),
      session_(session),
      tools_(tools),
      recorder_(recorder),
      acceptor_([&] {
        const tcp::endpoint endpoint(asio::ip::make_address(options.host), options.port);
        tcp::acceptor acceptor(io);
        acceptor.open(endpoint.protocol());
        acceptor.set_option(tcp::acceptor::reuse_address(true));
        acceptor.bind(endpoint);
        acceptor.listen();
        return acceptor;
      }()),
      tcp_port_(acceptor_.local_endpoint().port()),
      udp_(io, udp::endpoint(acceptor_.local_endpoint().address(), tcp_port_), server_inspector(key, session)),
      udp_sealer_(key, session, wire::kServerSender),
      slots_(static_cast<std::size_t>(welcome_.users_size())) {
  welcome_.set_server_udp_port(udp_.port());
}

ConnectionHandler::~ConnectionHandler() = default;

void ConnectionHandler::start() {
  accept();
  udp_.start([this](wire::Datagram&& datagram, const udp::endpoint&, std::int64_t arrival_ns) {
    receive_datagram(std::move(datagram), arrival_ns);
  });
}

int ConnectionHandler::users() const {
  int users = 0;
  for (const ParticipantPtr& participant : slots_) users += participant != nullptr;
  return users;
}

ConnectionCounters ConnectionHandler::counters() const {
  ConnectionCounters counters = counters_;
  counters.datagrams_sent = udp_.sent();
  return counters;
}

// ---- control connections ----

void ConnectionHandler::accept() {
  acceptor_.async_accept([this](std::error_code error, tcp::socket socket) {
    if (error) {
      if (error != asio::error::operation_aborted) spdlog::warn("accept failed: {}", error.message());
      return;
    }
    socket.set_option(tcp::no_delay(true));
    auto participant = std::make_shared<Participant>(key_, session_, options_.shift);
    const std::weak_ptr<Participant> weak = participant;
    net::FramedConnection::Handlers handlers;
    handlers.on_control = [this, weak](const wire::Control& control) {
      if (const ParticipantPtr p = weak.lock()) handle_control(p, control);
    };
    handlers.on_close = [this, weak](net::CloseCause cause, const std::string& why) {
      const ParticipantPtr p = weak.lock();
      if (!p) return;
      switch (cause) {
        case net::CloseCause::peer_closed: leave(p, "disconnected"); return;
        case net::CloseCause::rejected_frame:
          ++counters_.frames_rejected;
          spdlog::warn("control connection from {}: {}", p->connection->peer(), why);
          leave(p, "protocol error");
          return;
        case net::CloseCause::write_queue_full: spdlog::warn("control connection to {}: {}", p->connection->peer(), why); break;
        case net::CloseCause::io_error: break;
      }
      leave(p, why);
    };
    participant->connection = net::FramedConnection::start(std::move(socket), wire::FrameReader(key_), std::move(handlers));
    participants_.push_back(participant);
    accept();
  });
}

void ConnectionHandler::handle_control(const ParticipantPtr& participant, const wire::Control& control) {
  if (control.has_join()) join(participant, control.join());
  else if (control.has_bye()) leave(participant, "left: " + control.bye().reason());
  else if (control.has_status() && participant->slot >= 0) client_status(*participant, control.status());
}

void ConnectionHandler::client_status(const Participant& participant, const wire::ClientStatus& status) {
  const auto& s = status;
  for (double value : {s.haptic_rate_hz(), s.period_p99_us(), s.ir_age_p99_ms(), s.one_way_delay_p99_ms(),
                       s.timer_floor_p99_us(), s.peak_force(), s.elapsed_s()})
    if (!std::isfinite(value)) {
      ++counters_.frames_rejected;
      spdlog::warn("status of '{}' (slot {}) ignored: a value is not finite", participant.user_name, participant.slot);
      return;
    }
  if (recorder_) {
    record::ReceivedClientStatus received;
    received.set_receive_time_ns(wire::monotonic_now_ns());
    received.set_slot(static_cast<std::uint32_t>(participant.slot));
    received.set_user(participant.user_name);
    *received.mutable_status() = status;
    recorder_->client_status(received);
  }
  if (on_status_) on_status_(participant.slot, participant.user_name, status);
}

void ConnectionHandler::join(const ParticipantPtr& participant, const wire::Join& request) {
  if (participant->slot >= 0) return;
  int slot = -1;
  if (request.requested_slot() > 0) {
    const auto wanted = static_cast<int>(request.requested_slot() - 1);
    if (wanted < slots() && !slots_[static_cast<std::size_t>(wanted)]) slot = wanted;
  } else {
    for (int s = 0; s < slots() && slot < 0; ++s)
      if (!slots_[static_cast<std::size_t>(s)]) slot = s;
  }
  const std::string& peer = participant->connection->peer();
  if (slot < 0) {
    send_error(participant, "session_full", fmt::format("no free user slot (the scene has {} tools)", slots()));
    spdlog::warn("{} ('{}') refused: no free slot", peer, request.user_name());
    return;
  }
  participant->slot = slot;
  participant->user_name = request.user_name();
  participant->udp_endpoint =
      udp::endpoint(participant->connection->peer_address(), static_cast<std::uint16_t>(request.udp_port()));
  slots_[static_cast<std::size_t>(slot)] = participant;
  udp_.inspector().allow_sender(wire::sender_of_slot(static_cast<std::uint32_t>(slot)));
  tools_.join(slot);

  wire::Control control;
  wire::Welcome* welcome = control.mutable_welcome();
  *welcome = welcome_;
  welcome->set_slot(static_cast<std::uint32_t>(slot));
  for (int s = 0; s < slots(); ++s)
    if (const ParticipantPtr& user = slots_[static_cast<std::size_t>(s)]) welcome->mutable_users(s)->set_user_name(user->user_name);
  send_control(participant, control);
  const std::string& tool = welcome_.users(slot).tool_name();
  spdlog::info("user '{}' joined from {} as slot {} (tool {})", participant->user_name, peer, slot, tool);
  broadcast_event("user_joined", fmt::format("{} took tool {}", participant->user_name, tool),
                  record::EventUser{participant->user_name, static_cast<std::uint32_t>(slot)});
}

void ConnectionHandler::leave(const ParticipantPtr& participant, const std::string& why) {
  if (participant->gone) return;
  participant->gone = true;
  participant->connection->close();
  std::erase(participants_, participant);
  const int slot = participant->slot;
  if (slot < 0 || slots_[static_cast<std::size_t>(slot)] != participant) return;
  slots_[static_cast<std::size_t>(slot)].reset();
  auto timer = std::make_shared<asio::steady_timer>(io_, std::chrono::milliseconds(kLeftSenderGrace_ms));
  timer->async_wait([this, timer, slot](std::error_code) {
    if (!slots_[static_cast<std::size_t>(slot)]) udp_.inspector().forget_sender(wire::sender_of_slot(static_cast<std::uint32_t>(slot)));
  });
  tools_.release(slot);
  spdlog::info("user '{}' (slot {}) left: {}; its tool is released", participant->user_name, slot, why);
  broadcast_event("user_left", fmt::format("{} left ({})", participant->user_name, why),
                  record::EventUser{participant->user_name, static_cast<std::uint32_t>(slot)});
}

void ConnectionHandler::broadcast_event(const std::string& kind, const std::string& text, const record::EventUser& user) {
  if (recorder_) recorder_->event(wire::monotonic_now_ns(), kind, text, user);
  for (const ParticipantPtr& participant : slots_) {
    if (!participant) continue;
    wire::Control control;
    control.mutable_event()->set_kind(kind);
    control.mutable_event()->set_text(text);
    send_control(participant, control);
  }
}

void ConnectionHandler::send_error(const ParticipantPtr& participant, const std::string& code, const std::string& text) {
  wire::Control control;
  control.mutable_error()->set_code(code);
  control.mutable_error()->set_text(text);
  send_control(participant, control);
}

void ConnectionHandler::send_control(const ParticipantPtr& participant, wire::Control& control, bool newest_wins) {
  if (participant->gone) return;
  const net::FrameKind kind = newest_wins ? net::FrameKind::newest_wins : net::FrameKind::must_arrive;
  // The TCP link keeps order and loses nothing: every frame is delivered, perhaps later.
  net::deliver_over(participant->to_client_tcp, io_, wire::monotonic_now_ns(),
                    [this, participant, kind, frame = participant->sealer.seal(control)](std::int64_t) mutable {
                      if (participant->gone) return;
                      ++counters_.frames_sent;
                      if (participant->connection->send(std::move(frame), kind) == net::FramedConnection::Sent::queued_after_drop)
                        ++counters_.frames_dropped;
                    });
}

void ConnectionHandler::say_goodbye(const std::string& reason) {
  for (const ParticipantPtr& participant : slots_)
    if (participant) {
      wire::Control control;
      control.mutable_bye()->set_reason(reason);
      send_control(participant, control);
    }
  std::error_code ignored;
  acceptor_.close(ignored);
}

void ConnectionHandler::close_all(const std::string& why) {
  udp_.close();
  for (const ParticipantPtr& participant : std::vector(participants_)) leave(participant, why);
}

void ConnectionHandler::send(Outbox outbox) {
  for (ToSlot<wire::Control>& ir : outbox.irs)
    if (const ParticipantPtr& participant = slots_[static_cast<std::size_t>(ir.slot)]) send_control(participant, ir.message, true);
  for (ToSlot<wire::Datagram>& datagram : outbox.datagrams)
    if (const ParticipantPtr& participant = slots_[static_cast<std::size_t>(datagram.slot)]) send_datagram(*participant, datagram.message);
}

// ---- datagrams ----

void ConnectionHandler::send_datagram(Participant& participant, wire::Datagram& datagram) {
  const udp::endpoint to = participant.udp_endpoint;
  const bool delivered = net::deliver_over(participant.to_client_udp, io_, wire::monotonic_now_ns(),
                                           [this, to, bytes = udp_sealer_.seal(datagram)](std::int64_t) mutable {
                                             udp_.send(std::move(bytes), to);
                                           });
  if (!delivered) ++counters_.dropped_to_clients;
}

void ConnectionHandler::receive_datagram(wire::Datagram&& datagram, std::int64_t arrival_ns) {
  // The inspector only accepts the senders of joined slots (or of slots left a moment ago).
  const int slot = static_cast<int>(datagram.header().sender()) - 1;
  if (slot < 0 || slot >= slots() || !slots_[static_cast<std::size_t>(slot)]) return;
  const bool delivered = net::deliver_over(
      slots_[static_cast<std::size_t>(slot)]->from_client_udp, io_, arrival_ns,
      [this, slot, datagram = std::move(datagram)](std::int64_t delivered_ns) { handle_datagram(datagram, slot, delivered_ns); });
  if (!delivered) ++counters_.dropped_from_clients;
}

void ConnectionHandler::handle_datagram(const wire::Datagram& datagram, int slot, std::int64_t arrival_ns) {
  if (!slots_[static_cast<std::size_t>(slot)]) return;  // left while the datagram was delayed
  if (recorder_) recorder_->datagram_in(arrival_ns, datagram);
  if (datagram.has_tool()) {
    const wire::ToolSample& sample = datagram.tool();
    if (static_cast<int>(sample.user()) != slot) return;  // a user speaks for its own tool only
    if (!tools_.update(slot, sample.valid(), wire::from_wire(sample.position()), sample.sample_time_ns(), arrival_ns))
      return;  // older than the sample held
    // Relay to the other users, who play it out against their own clocks.
    for (int other = 0; other < slots(); ++other) {
      const ParticipantPtr& participant = slots_[static_cast<std::size_t>(other)];
      if (other == slot || !participant) continue;
      wire::Datagram relay;
      *relay.mutable_tool() = sample;
      send_datagram(*participant, relay);
      ++counters_.datagrams_relayed;
    }
  } else if (datagram.has_ping()) {
    wire::Datagram pong;
    pong.mutable_pong()->set_client_send_ns(datagram.ping().client_send_ns());
    pong.mutable_pong()->set_server_receive_ns(arrival_ns);
    pong.mutable_pong()->set_server_send_ns(wire::monotonic_now_ns());
    send_datagram(*slots_[static_cast<std::size_t>(slot)], pong);
  }
}

}  // namespace cohaptic
