#include "server/connection_handler.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "common/delay/link_delay.h"
#include "common/util/monotonic_clock.h"
#include "common/util/printable.h"
#include "net/delayed_delivery.h"
#include "proto/wire/header.h"
#include "proto/wire/traffic_keys.h"
#include "proto/wire/user_name.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic {

using asio::ip::tcp;
using asio::ip::udp;

// One control connection; a user once it has joined.
struct ConnectionHandler::Participant {
  std::shared_ptr<net::FramedConnection> connection;
  wire::Challenge challenge = wire::random_challenge();  // in the greeting; the Join must carry it
  wire::FrameSealer sealer;  // this connection's frames; keyed at the join
  std::optional<wire::DatagramSealer>
      datagram_sealer;  // the datagrams to this user, from the join on
  int slot = -1;
  std::string user_name;
  udp::endpoint udp_endpoint;
  LinkDelay to_client_udp, to_client_tcp, from_client_udp;
  asio::steady_timer join_timer;
  net::TokenBucket datagram_budget;  // set at the join, from the user's haptic rate
  // A datagram came from it: it has taken in the welcome, and knows the server's datagrams.
  // Until then none are sent to it (it would refuse them as from an unknown sender).
  bool heard_over_udp = false;
  bool gone = false;
  Participant(asio::io_context& io, std::uint64_t session, const LinkDelaySettings& shift,
              bool encrypt)
      : sealer(session, wire::kServerSender, encrypt),
        to_client_udp(shift, false),
        to_client_tcp(shift, true),
        from_client_udp(shift, false),
        join_timer(io) {}
};

namespace {

std::vector<wire::TrafficKey> every_slot_key(const wire::SessionKey& key, std::size_t slots) {
  std::vector<wire::TrafficKey> keys;
  for (std::size_t slot = 0; slot < slots; ++slot)
    keys.push_back(wire::participant_key(key, static_cast<std::uint32_t>(slot)));
  return keys;
}

}  // namespace

ConnectionHandler::ConnectionHandler(asio::io_context& io, const ServeOptions& options,
                                     wire::Welcome welcome, const wire::SessionKey& key,
                                     std::uint64_t session, int max_participants, ToolInputs& tools,
                                     record::SessionRecorder* recorder)
    : io_(io),
      options_(options),
      welcome_(std::move(welcome)),
      slot_keys_(every_slot_key(key, static_cast<std::size_t>(welcome_.users_size()))),
      joining_key_(wire::joining_key(key)),
      session_(session),
      max_participants_(max_participants > 0 ? max_participants : welcome_.users_size()),
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
      accept_retry_(io),
      tcp_port_(acceptor_.local_endpoint().port()),
      udp_(io, udp::endpoint(acceptor_.local_endpoint().address(), tcp_port_),
           std::make_unique<wire::DatagramInspector>(session, !options.encrypt)),
      slots_(static_cast<std::size_t>(welcome_.users_size())),
      link_delay_(options.shift) {
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
  counters.datagrams_dropped_by_kernel = udp_.kernel_dropped();
  return counters;
}

void ConnectionHandler::warn_throttled(const std::string& message) {
  const std::int64_t now = monotonic_now_ns();
  if (now - last_warning_ns_ < 1'000'000'000) {
    ++warnings_held_;
    return;
  }
  if (warnings_held_ > 0)
    spdlog::warn("{} (and {} more such since the last one logged)", message, warnings_held_);
  else
    spdlog::warn("{}", message);
  last_warning_ns_ = now;
  warnings_held_ = 0;
}

// ---- control connections ----

void ConnectionHandler::accept() {
  acceptor_.async_accept([this](std::error_code error, tcp::socket socket) {
    if (error == asio::error::operation_aborted || !acceptor_.is_open()) return;  // closing
    if (error) {
      ++counters_.accept_errors;
      warn_throttled(fmt::format("accept failed: {}; accepting again in {} ms", error.message(),
                                 kAcceptRetry.count()));
      accept_retry_.expires_after(kAcceptRetry);
      accept_retry_.async_wait([this](std::error_code timer_error) {
        if (!timer_error) accept();
      });
      return;
    }
    ++counters_.connections;
    std::error_code ignored;
    const asio::ip::address source = socket.remote_endpoint(ignored).address();
    make_room_for_unjoined(source);
    socket.set_option(tcp::no_delay(true));
    socket.set_option(asio::socket_base::send_buffer_size(kControlSendBufferBytes));
    auto participant = std::make_shared<Participant>(io_, session_, link_delay_, options_.encrypt);
    const std::weak_ptr<Participant> weak = participant;
    net::FramedConnection::Handlers handlers;
    handlers.on_control = [this, weak](const wire::Control& control) {
      if (const ParticipantPtr p = weak.lock()) handle_control(p, control);
    };
    handlers.on_close = [this, weak](net::CloseCause cause, const std::string& why) {
      if (const ParticipantPtr p = weak.lock()) closed(p, cause, why);
    };
    wire::FrameReader reader(
        [this, weak](std::uint32_t sender) -> const wire::TrafficKey* {
          const ParticipantPtr p = weak.lock();
          return p ? key_for(*p, sender) : nullptr;
        },
        {.expect_greeting = false,
         .allow_cleartext = !options_.encrypt,
         .max_body_bytes = kMaxJoinFrameBytes});
    participant->connection =
        net::FramedConnection::start(std::move(socket), std::move(reader), std::move(handlers));
    participants_.push_back(participant);
    send_bytes(participant, wire::encode_greeting(participant->challenge),
               net::FrameKind::must_arrive, false);
    participant->join_timer.expires_after(kJoinTimeout);
    participant->join_timer.async_wait([this, weak](std::error_code timer_error) {
      const ParticipantPtr p = weak.lock();
      if (timer_error || !p || p->gone || p->slot >= 0) return;
      ++counters_.join_timeouts;
      warn_throttled(fmt::format("connection from {} closed: no join within {} s",
                                 p->connection->peer(), kJoinTimeout.count()));
      leave(p, "no join in time");
    });
    accept();
  });
}

// The unjoined connections are bounded per source address and in all. A full source, or a
// full server, closes its oldest unjoined connection rather than refusing the new one: a
// client joins within a round trip, so an attacker would have to open connections faster
// than that to push it out, and one source can only ever push out its own.
void ConnectionHandler::make_room_for_unjoined(const asio::ip::address& source) {
  std::size_t from_source = 0, in_all = 0;
  ParticipantPtr oldest_from_source, oldest;  // participants_ is in the order accepted
  for (const ParticipantPtr& participant : participants_) {
    if (participant->slot >= 0) continue;
    ++in_all;
    if (!oldest) oldest = participant;
    if (participant->connection->peer_address() == source) {
      ++from_source;
      if (!oldest_from_source) oldest_from_source = participant;
    }
  }
  const ParticipantPtr evicted = from_source >= kMaxUnjoinedPerSource ? oldest_from_source
                                 : in_all >= kMaxUnjoinedConnections  ? oldest
                                                                      : nullptr;
  if (!evicted) return;
  ++counters_.unjoined_evicted;
  warn_throttled(fmt::format(
      "connection from {} closed before its join to make room: {} not joined from {}, {} in all",
      evicted->connection->peer(), from_source, source.to_string(), in_all));
  leave(evicted, "closed to make room for a newer connection");
}

void ConnectionHandler::closed(const ParticipantPtr& participant, net::CloseCause cause,
                               const std::string& why) {
  const std::string& peer = participant->connection->peer();
  switch (cause) {
    case net::CloseCause::peer_closed:
      leave(participant, "disconnected");
      return;
    case net::CloseCause::rejected_frame:
      reject_frame(participant,
                   participant->connection->rejection().value_or(wire::Rejection::truncated), why);
      return;
    case net::CloseCause::write_queue_full:
      ++counters_.queue_overflows;
      spdlog::warn("control connection to {}: {}", peer, why);
      break;
    case net::CloseCause::write_stalled:
      ++counters_.write_stalls;
      spdlog::warn("control connection to {}: {}", peer, why);
      break;
    case net::CloseCause::io_error:
      break;
  }
  leave(participant, why);
}

void ConnectionHandler::reject_frame(const ParticipantPtr& participant, wire::Rejection reason,
                                     const std::string& why) {
  ++counters_.frames_rejected;
  ++counters_.frames_rejected_by_reason[static_cast<std::size_t>(reason)];
  warn_throttled(fmt::format("control connection from {} closed ({}): {}",
                             participant->connection->peer(), wire::to_string(reason), why));
  leave(participant, "protocol error");
}

const wire::TrafficKey* ConnectionHandler::key_for(const Participant& participant,
                                                   std::uint32_t sender) const {
  if (participant.slot >= 0)  // joined: its own slot's key only
    return sender == wire::sender_of_slot(static_cast<std::uint32_t>(participant.slot))
               ? &slot_keys_[static_cast<std::size_t>(participant.slot)]
               : nullptr;
  if (sender == wire::kJoiningSender) return &joining_key_;
  if (sender != wire::kServerSender && sender - 1 < slot_keys_.size())
    return &slot_keys_[sender - 1];
  return nullptr;
}

void ConnectionHandler::handle_control(const ParticipantPtr& participant,
                                       const wire::Control& control) {
  if (control.has_join())
    join(participant, control);
  else if (control.has_bye())
    leave(participant, "left: " + control.bye().reason());
  else if (control.has_status() && participant->slot >= 0)
    client_status(*participant, control.status());
}

void ConnectionHandler::client_status(const Participant& participant,
                                      const wire::ClientStatus& status) {
  const auto& s = status;
  for (double value :
       {s.haptic_rate_hz(), s.period_p99_us(), s.ir_age_p99_ms(), s.one_way_delay_p99_ms(),
        s.timer_floor_p99_us(), s.peak_force(), s.elapsed_s()})
    if (!std::isfinite(value)) {
      ++counters_.frames_rejected;
      spdlog::warn("status of '{}' (slot {}) ignored: a value is not finite", participant.user_name,
                   participant.slot);
      return;
    }
  if (recorder_) {
    record::ReceivedClientStatus received;
    received.set_receive_time_ns(monotonic_now_ns());
    received.set_slot(static_cast<std::uint32_t>(participant.slot));
    received.set_user(participant.user_name);
    *received.mutable_status() = status;
    recorder_->client_status(received);
  }
  if (on_status_) on_status_(participant.slot, participant.user_name, status);
}

// The slot `request` may take (-1 after a refusal, sent). `sender`: whose key sealed it.
int ConnectionHandler::take_slot(const ParticipantPtr& participant, const wire::Join& request,
                                 std::uint32_t sender) {
  const auto refuse = [&](const std::string& code, const std::string& text) {
    ++counters_.joins_refused;
    send_error(participant, code, text);
    spdlog::warn("{} ('{}') refused: {}", participant->connection->peer(),
                 printable(request.user_name()), text);
    return -1;
  };
  if (const std::string problem = wire::user_name_problem(request.user_name()); !problem.empty())
    return refuse("bad_user_name", problem);
  const double rate = request.haptic_rate_hz();
  if (!(rate >= 0 && rate <= kMaxClientHapticRateHz))
    return refuse("bad_rate", fmt::format("a haptic rate of {} Hz: it must be at most {:.0f} Hz",
                                          rate, kMaxClientHapticRateHz));
  int wanted = request.requested_slot() > 0 ? static_cast<int>(request.requested_slot() - 1) : -1;
  if (sender != wire::kJoiningSender) {  // a participant key: its slot, and no other
    const int own = static_cast<int>(sender - 1);
    if (wanted >= 0 && wanted != own)
      return refuse(
          "wrong_slot",
          fmt::format("the key given is slot {}'s, and slot {} was asked for", own, wanted));
    wanted = own;
  }
  if (users() >= max_participants_)
    return refuse("session_full",
                  fmt::format("the session is full: the scene allows {} participant{} at once "
                              "(network.max_participants)",
                              max_participants_, max_participants_ == 1 ? "" : "s"));
  if (wanted >= slots())
    return refuse("session_full",
                  fmt::format("slot {} does not exist: the scene has {} tools", wanted, slots()));
  if (wanted >= 0) {
    if (slots_[static_cast<std::size_t>(wanted)])
      return refuse("session_full", fmt::format("slot {} is taken", wanted));
    return wanted;
  }
  for (int s = 0; s < slots(); ++s)
    if (!slots_[static_cast<std::size_t>(s)]) return s;
  return refuse("session_full", fmt::format("no free user slot (the scene has {} tools)", slots()));
}

void ConnectionHandler::join(const ParticipantPtr& participant, const wire::Control& control) {
  if (participant->slot >= 0) return;
  const wire::Join& request = control.join();
  const std::uint32_t sender =
      control.header().sender();  // the envelope's: its key opened the frame
  if (!wire::is_challenge(request.challenge(), participant->challenge)) {
    reject_frame(participant, wire::Rejection::replayed,
                 "a join without this connection's challenge (replayed?)");
    return;
  }
  // The reply goes under the key the join came with; what follows under the slot's.
  participant->sealer.set_key(sender == wire::kJoiningSender ? joining_key_
                                                             : slot_keys_[sender - 1]);
  const int slot = take_slot(participant, request, sender);
  if (slot < 0) return;
  const wire::TrafficKey& key = slot_keys_[static_cast<std::size_t>(slot)];
  participant->slot = slot;
  participant->connection->set_max_frame_bytes(kMaxClientFrameBytes);
  participant->user_name = request.user_name();
  participant->udp_endpoint = udp::endpoint(participant->connection->peer_address(),
                                            static_cast<std::uint16_t>(request.udp_port()));
  participant->datagram_sealer.emplace(key, session_, wire::kServerSender, options_.encrypt);
  const double rate =
      request.haptic_rate_hz() > 0 ? request.haptic_rate_hz() : welcome_.haptic_rate_hz();
  participant->datagram_budget = {rate, kUserDatagramsPerTick * rate, rate, monotonic_now_ns()};
  slots_[static_cast<std::size_t>(slot)] = participant;
  udp_.inspector().allow_sender(wire::sender_of_slot(static_cast<std::uint32_t>(slot)), key,
                                request.datagram_salt(), request.datagram_sequence());
  udp_.trust(participant->udp_endpoint);
  tools_.join(slot);
  ++counters_.joins;

  wire::Control reply;
  wire::Welcome* welcome = reply.mutable_welcome();
  *welcome = welcome_;
  welcome->set_slot(static_cast<std::uint32_t>(slot));
  welcome->set_client_challenge(request.client_challenge());
  welcome->set_datagram_salt(participant->datagram_sealer->salt());
  for (int s = 0; s < slots(); ++s)
    if (const ParticipantPtr& user = slots_[static_cast<std::size_t>(s)])
      welcome->mutable_users(s)->set_user_name(user->user_name);
  send_control(participant, reply);
  participant->sealer.set_key(key);
  const std::string& tool = welcome_.users(slot).tool_name();
  spdlog::info("user '{}' joined from {} as slot {} (tool {})", participant->user_name,
               participant->connection->peer(), slot, tool);
  broadcast_event("user_joined", fmt::format("{} took tool {}", participant->user_name, tool),
                  record::EventUser{participant->user_name, static_cast<std::uint32_t>(slot)});
}

void ConnectionHandler::leave(const ParticipantPtr& participant, const std::string& why) {
  if (participant->gone) return;
  participant->gone = true;
  participant->connection->close();
  participant->join_timer.cancel();
  std::erase(participants_, participant);
  const int slot = participant->slot;
  if (slot < 0 || slots_[static_cast<std::size_t>(slot)] != participant) return;
  slots_[static_cast<std::size_t>(slot)].reset();
  udp_.distrust(participant->udp_endpoint);
  auto timer =
      std::make_shared<asio::steady_timer>(io_, std::chrono::milliseconds(kLeftSenderGrace_ms));
  timer->async_wait([this, timer, slot](std::error_code) {
    if (!slots_[static_cast<std::size_t>(slot)])
      udp_.inspector().forget_sender(wire::sender_of_slot(static_cast<std::uint32_t>(slot)));
  });
  tools_.release(slot);
  spdlog::info("user '{}' (slot {}) left: {}; its tool is released", participant->user_name, slot,
               why);
  broadcast_event("user_left", fmt::format("{} left ({})", participant->user_name, why),
                  record::EventUser{participant->user_name, static_cast<std::uint32_t>(slot)});
}

void ConnectionHandler::broadcast_event(const std::string& kind, const std::string& text,
                                        const record::EventUser& user) {
  if (recorder_) recorder_->event(monotonic_now_ns(), kind, text, user);
  for (const ParticipantPtr& participant : slots_) {
    if (!participant) continue;
    wire::Control control;
    control.mutable_event()->set_kind(kind);
    control.mutable_event()->set_text(text);
    send_control(participant, control);
  }
}

void ConnectionHandler::send_error(const ParticipantPtr& participant, const std::string& code,
                                   const std::string& text) {
  wire::Control control;
  control.mutable_error()->set_code(code);
  control.mutable_error()->set_text(text);
  send_control(participant, control);
}

void ConnectionHandler::send_bytes(const ParticipantPtr& participant,
                                   std::vector<std::uint8_t> bytes, net::FrameKind kind,
                                   bool frame) {
  if (participant->gone) return;
  // The TCP link keeps order and loses nothing: every frame is delivered, perhaps later.
  net::deliver_over(
      participant->to_client_tcp, io_, monotonic_now_ns(),
      [this, participant, kind, frame, bytes = std::move(bytes)](std::int64_t) mutable {
        if (participant->gone) return;
        counters_.frames_sent += frame;
        if (participant->connection->send(std::move(bytes), kind) ==
            net::FramedConnection::Sent::queued_after_drop)
          ++counters_.frames_dropped;
      });
}

void ConnectionHandler::send_control(const ParticipantPtr& participant, wire::Control& control,
                                     bool newest_wins) {
  if (participant->gone) return;
  send_bytes(participant, participant->sealer.seal(control),
             newest_wins ? net::FrameKind::newest_wins : net::FrameKind::must_arrive, true);
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
  accept_retry_.cancel();
}

void ConnectionHandler::close_all(const std::string& why) {
  udp_.close();
  for (const ParticipantPtr& participant : std::vector(participants_)) leave(participant, why);
}

void ConnectionHandler::set_link_delay(const LinkDelaySettings& settings) {
  validate(settings);
  link_delay_ = settings;
  for (const ParticipantPtr& participant : participants_)
    for (LinkDelay* link :
         {&participant->to_client_udp, &participant->to_client_tcp, &participant->from_client_udp})
      link->set_settings(settings);
}

void ConnectionHandler::send(Outbox outbox) {
  if (outbox.link_delay) set_link_delay(*outbox.link_delay);
  if (outbox.protocol_switch) {
    welcome_.set_protocol(*outbox.protocol_switch);  // users who join later are told it too
    for (const ParticipantPtr& participant : slots_)
      if (participant) {
        wire::Control control;
        control.mutable_protocol_switch()->set_protocol(*outbox.protocol_switch);
        send_control(participant, control);
      }
  }
  for (ToSlot<wire::Control>& ir : outbox.irs)
    if (const ParticipantPtr& participant = slots_[static_cast<std::size_t>(ir.slot)])
      send_control(participant, ir.message, !ir.must_arrive);
  for (ToSlot<wire::Datagram>& datagram : outbox.datagrams)
    if (const ParticipantPtr& participant = slots_[static_cast<std::size_t>(datagram.slot)])
      send_datagram(*participant, datagram.message);
}

// ---- datagrams ----

void ConnectionHandler::send_datagram(Participant& participant, wire::Datagram& datagram) {
  if (!participant.heard_over_udp) return;
  const udp::endpoint to = participant.udp_endpoint;
  const bool delivered =
      net::deliver_over(participant.to_client_udp, io_, monotonic_now_ns(),
                        [this, to, bytes = participant.datagram_sealer->seal(datagram)](
                            std::int64_t) mutable { udp_.send(std::move(bytes), to); });
  if (!delivered) ++counters_.dropped_to_clients;
}

void ConnectionHandler::receive_datagram(wire::Datagram&& datagram, std::int64_t arrival_ns) {
  // The inspector only accepts the senders of joined slots (or of slots left a moment ago).
  const int slot = static_cast<int>(datagram.header().sender()) - 1;
  if (slot < 0 || slot >= slots() || !slots_[static_cast<std::size_t>(slot)]) return;
  Participant& user = *slots_[static_cast<std::size_t>(slot)];
  user.heard_over_udp = true;
  if (!user.datagram_budget.try_take(arrival_ns)) {
    ++counters_.datagrams_over_budget;
    warn_throttled(fmt::format("datagrams of '{}' (slot {}) dropped: more than {:.0f} a second",
                               user.user_name, slot, user.datagram_budget.refill_per_s));
    return;
  }
  const bool delivered =
      net::deliver_over(user.from_client_udp, io_, arrival_ns,
                        [this, slot, datagram = std::move(datagram)](std::int64_t delivered_ns) {
                          handle_datagram(datagram, slot, delivered_ns);
                        });
  if (!delivered) ++counters_.dropped_from_clients;
}

void ConnectionHandler::handle_datagram(const wire::Datagram& datagram, int slot,
                                        std::int64_t arrival_ns) {
  if (!slots_[static_cast<std::size_t>(slot)]) return;  // left while the datagram was delayed
  if (recorder_) recorder_->datagram_in(arrival_ns, datagram);
  if (datagram.has_tool()) {
    const wire::ToolSample& sample = datagram.tool();
    if (static_cast<int>(sample.user()) != slot) return;  // a user speaks for its own tool only
    if (!tools_.update(slot, sample.valid(), wire::from_wire(sample.position()), sample.buttons(),
                       sample.sample_time_ns(), arrival_ns))
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
    pong.mutable_pong()->set_server_send_ns(monotonic_now_ns());
    send_datagram(*slots_[static_cast<std::size_t>(slot)], pong);
  }
}

}  // namespace cohaptic
