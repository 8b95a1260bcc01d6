#include "client/client_network.h"

#include <spdlog/spdlog.h>

#include <asio.hpp>
#include <chrono>
#include <condition_variable>
#include <future>
#include <mutex>
#include <thread>

#include "client/client_recording.h"
#include "client/client_status.h"
#include "client/clock_sync.h"
#include "client/ir_intake.h"
#include "client/server_connection.h"
#include "client/welcome.h"
#include "common/util/monotonic_clock.h"
#include "net/datagram_endpoint.h"
#include "proto/record/session_recorder.h"
#include "proto/wire/header.h"
#include "proto/wire/sealer.h"
#include "proto/wire/session_key.h"
#include "proto/wire/traffic_keys.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic {

using asio::ip::udp;

namespace {

/// How often the haptic thread's rings are drained: its own samples leave within a tick or two.
constexpr std::chrono::milliseconds kDrainPeriod{1};
/// Time the goodbye gets to leave before the I/O stops.
constexpr std::chrono::milliseconds kGoodbyeGrace{50};

std::int64_t now_ns() { return monotonic_now_ns(); }

const char* event_name(HapticEventKind kind) {
  switch (kind) {
    case HapticEventKind::non_finite:
      return "non-finite force: zero output";
    case HapticEventKind::ir_switched:
      return "IR switched";
    case HapticEventKind::fading:
      return "stale IR: fading";
    case HapticEventKind::started_realtime:
      return "haptic thread running SCHED_FIFO with locked memory";
    case HapticEventKind::realtime_refused:
      return "SCHED_FIFO or mlockall refused (not permitted): running best effort";
  }
  return "?";
}

// The keys of the key file, or the public development session key.
std::variant<wire::SessionKey, wire::ParticipantKey> client_keys(const ClientOptions& options) {
  if (!options.key_file) {
    spdlog::warn("no --key-file: using the public development key");
    return wire::development_key();
  }
  return wire::load_key_file(*options.key_file);
}

// The slot to ask for: --slot, or a participant key's own (and no other).
int requested_slot(const ClientOptions& options, const wire::ClientKeys& keys) {
  const std::optional<std::uint32_t> fixed = keys.fixed_slot();
  if (!fixed) return options.requested_slot;
  if (options.requested_slot >= 0 && static_cast<std::uint32_t>(options.requested_slot) != *fixed)
    throw Error(
        fmt::format("--slot {}, but the key file is participant {}'s: it can only join slot {}",
                    options.requested_slot, *fixed, *fixed));
  return static_cast<int>(*fixed);
}

}  // namespace

struct ClientNetwork::Impl {
  ClientOptions options;
  HapticChannels& channels;
  std::atomic<bool>& stop_requested;
  wire::ClientKeys keys;
  int slot_asked;

  asio::io_context io;
  net::DatagramEndpoint udp;
  wire::DatagramSealer udp_sealer;
  udp::endpoint server_udp;
  ServerConnection connection;
  ClockSync clock;
  IrIntake irs;
  asio::steady_timer drain_timer{io};
  asio::steady_timer status_timer{io};
  const HapticMetrics* haptic_metrics = nullptr;  // from report_status() on
  const TimerFloors* floors = nullptr;
  asio::signal_set signals{io, SIGINT, SIGTERM};
  std::thread thread;

  // Welcome hand-off to start().
  std::mutex welcome_mutex;
  std::condition_variable welcome_ready;
  std::optional<WelcomeInfo> welcome;
  std::string refusal;
  bool connected = false;  // welcomed, and not lost since
  bool ever_connected = false;

  // Counters (I/O thread; read after stop()).
  std::uint64_t reconnects = 0, forces_received = 0, remote_samples = 0, non_finite_events = 0;
  std::unique_ptr<record::SessionRecorder> recorder;  // from record_session() on
  std::optional<WelcomeInfo> welcomed;                // the last welcome, for the recording
  std::uint64_t session_id = 0;

  Impl(ClientOptions o, HapticChannels& c, std::atomic<bool>& stop)
      : options(std::move(o)),
        channels(c),
        stop_requested(stop),
        keys(client_keys(options)),
        slot_asked(requested_slot(options, keys)),
        // Datagrams are accepted from the server only, once the Welcome has named its key and salt.
        udp(io, udp::endpoint(asio::ip::make_address("0.0.0.0"), 0),
            std::make_unique<wire::DatagramInspector>(std::nullopt, !options.encrypt)),
        udp_sealer(0, 0, options.encrypt),
        connection(io, options.host, options.port, keys, options.encrypt,
                   {[this] { return join_request(); },
                    [this](const wire::Control& control) { handle_control(control); },
                    [this](const std::string& why) { lost(why); }}),
        clock(io, [this](wire::Datagram& ping) { send_datagram(ping); }),
        irs(channels.ir) {
    if (!options.encrypt)
      spdlog::warn(
          "--no-encryption: frames and datagrams travel in clear (authenticated, readable by "
          "anyone on the path)");
    spdlog::info("receiving datagrams on UDP port {}", udp.port());
  }

  // ---- control ----

  wire::Control join_request() const {
    wire::Control control;
    control.mutable_join()->set_user_name(options.user_name);
    control.mutable_join()->set_udp_port(udp.port());
    control.mutable_join()->set_requested_slot(
        slot_asked >= 0 ? static_cast<std::uint32_t>(slot_asked + 1) : 0);
    control.mutable_join()->set_datagram_salt(udp_sealer.salt());
    control.mutable_join()->set_datagram_sequence(udp_sealer.stamp().last_sequence());
    control.mutable_join()->set_haptic_rate_hz(options.haptic_rate_hz);
    return control;
  }

  void lost(const std::string& why) {
    if (!connected) return;
    if (recorder) recorder->event(now_ns(), "lost", why);
    spdlog::warn("lost the server ({}); zero force until it is back, reconnecting", why);
    connected = false;
  }

  void handle_control(const wire::Control& control) {
    if (control.has_welcome()) {
      joined(control.welcome(), control.header().session());
    } else if (control.has_ir()) {
      const std::int64_t arrival = now_ns();
      if (irs.receive(control.ir(), control.ByteSizeLong(), arrival) && recorder)
        recorder->ir(arrival, control.ir(), false, irs.warmed());
    } else if (control.has_compressed_ir()) {  // recorded as the block it came in
      const std::int64_t arrival = now_ns();
      if (irs.receive_compressed(control.compressed_ir(), control.ByteSizeLong(), arrival) &&
          recorder)
        recorder->ir_block(arrival, 0, control.compressed_ir(), false, irs.warmed());
    } else if (control.has_protocol_switch()) {
      const wire::Protocol protocol = control.protocol_switch().protocol();
      if (protocol != wire::P0 && protocol != wire::P1) {
        spdlog::warn("the server switched to protocol {}, neither P0 nor P1: ignored",
                     static_cast<int>(protocol));
        return;
      }
      const HapticProtocol now_served =
          protocol == wire::P1 ? HapticProtocol::p1 : HapticProtocol::p0;
      serve_protocol(now_served);
      spdlog::info("the server serves {} from now on",
                   now_served == HapticProtocol::p1 ? "P1" : "P0");
      if (recorder)
        recorder->event(now_ns(), "protocol", now_served == HapticProtocol::p1 ? "P1" : "P0");
    } else if (control.has_event()) {
      spdlog::info("server: {}", control.event().text());
    } else if (control.has_error()) {
      spdlog::error("server refused: {} ({})", control.error().text(), control.error().code());
      std::lock_guard lock(welcome_mutex);
      refusal = control.error().text();
      welcome_ready.notify_all();
    } else if (control.has_bye()) {
      connection.drop("server said goodbye: " + control.bye().reason());
    }
  }

  // The haptic loop changes over to `protocol` once what it needs has arrived after now.
  void serve_protocol(HapticProtocol protocol) {
    channels.protocol.back() = {protocol, now_ns()};
    channels.protocol.publish();
  }

  void joined(const wire::Welcome& message, std::uint64_t session) {
    WelcomeInfo info;
    try {
      info = welcome_info(message);
    } catch (const Error& error) {
      // Nothing of a welcome we cannot use reaches the haptic loop: start() fails with why.
      spdlog::error("{}", error.what());
      connection.drop(error.what());
      std::lock_guard lock(welcome_mutex);
      refusal = error.what();
      welcome_ready.notify_all();
      return;
    }
    udp.distrust(server_udp);
    server_udp = udp::endpoint(connection.server_address(),
                               static_cast<std::uint16_t>(message.server_udp_port()));
    udp.trust(server_udp);
    udp.inspector().set_expected_session(session);
    // The server's datagrams to us: our slot's key, its sealer's salt, a fresh replay window.
    // Our sequence numbers keep increasing across sessions, the server's sealer is new.
    udp.inspector().allow_sender(wire::kServerSender, connection.key(), message.datagram_salt());
    udp_sealer.set_key(connection.key());
    udp_sealer.stamp().set_session(session);
    udp_sealer.stamp().set_sender(wire::sender_of_slot(message.slot()));
    if (ever_connected) ++reconnects;
    ever_connected = connected = true;
    spdlog::info("joined '{}' as slot {} ({} protocol, force limit {:g} N)", info.scene_name,
                 info.slot, info.protocol == HapticProtocol::p1 ? "P1" : "P0", info.force_limit);
    clock.restart();
    session_id = session;
    welcomed = info;
    serve_protocol(info.protocol);  // a server met again may serve another one
    if (recorder)
      recorder->event(now_ns(), "joined",
                      fmt::format("session {:016x}, slot {}", session, info.slot));
    std::lock_guard lock(welcome_mutex);
    welcome = info;
    welcome_ready.notify_all();
  }

  // ---- datagrams ----

  void handle_datagram(const wire::Datagram& datagram, std::int64_t arrival) {
    if (recorder) recorder->datagram_in(arrival, datagram);
    clock.observe(datagram.header().sender_time_ns(), arrival);
    if (datagram.has_pong()) {
      clock.on_pong(datagram.pong(), arrival);
    } else if (datagram.has_tool()) {
      const wire::ToolSample& sample = datagram.tool();
      RemoteSample remote;
      remote.user = sample.user();
      remote.sample_time_ns = clock.to_client(sample.sample_time_ns());
      remote.arrival_ns = arrival;
      remote.position = wire::from_wire(sample.position());
      remote.valid = sample.valid();
      irs.see_remote_tool(remote.user, remote.position, remote.valid);
      channels.remote_samples.push(remote);
      ++remote_samples;
    } else if (datagram.has_keep_alive()) {
      channels.confirmation.back() = {datagram.keep_alive().ir_epoch(), arrival};
      channels.confirmation.publish();
    } else if (datagram.has_force()) {
      ForceSlot& slot = channels.force.back();
      slot.force = wire::from_wire(datagram.force().force());
      slot.arrival_ns = arrival;
      slot.epoch = datagram.force().ir_epoch();
      slot.valid = true;
      channels.force.publish();
      ++forces_received;
    }
  }

  void send_datagram(wire::Datagram& datagram) {
    if (!connected) return;
    udp.send(udp_sealer.seal(datagram), server_udp);
  }

  // ---- the haptic thread's rings: own samples out, events logged, ticks recorded ----

  void drain() {
    while (const auto own = channels.own_samples.pop()) {
      irs.see_own_tool(own->position, own->valid);
      wire::Datagram datagram;
      auto* sample = datagram.mutable_tool();
      const std::uint32_t sender = udp_sealer.stamp().sender();
      sample->set_user(sender > 0 ? sender - 1 : 0);
      sample->set_sample_time_ns(clock.to_server(own->sample_time_ns));
      *sample->mutable_position() =
          wire::to_wire(own->valid ? own->position : Eigen::Vector3d::Zero());
      sample->set_valid(own->valid);
      sample->set_buttons(own->buttons);
      send_datagram(datagram);
    }
    while (const auto event = channels.events.pop()) {
      if (recorder) recorder->event(event->time_ns, "haptic", event_name(event->kind));
      if (event->kind == HapticEventKind::non_finite) ++non_finite_events;
      if (event->kind == HapticEventKind::realtime_refused ||
          event->kind == HapticEventKind::non_finite)
        spdlog::warn("haptic: {}", event_name(event->kind));
      else
        spdlog::info("haptic: {}", event_name(event->kind));
    }
    while (const auto tick = channels.trace.pop())
      if (recorder) recorder->tick(haptic_tick_record(*tick));
    if (recorder) recorder->flush_if_due();
  }

  // ---- status reports ----

  void send_status() {
    if (!haptic_metrics || !connected) return;
    channels.progress.update();
    wire::Control control;
    *control.mutable_status() = client_status(channels.progress.front(), *haptic_metrics,
                                              floors->period_p99_us(), clock.one_way_delay());
    connection.send(control);
  }

  void schedule_status() {
    status_timer.expires_after(std::chrono::milliseconds(kStatusPeriod_ms));
    status_timer.async_wait([this](std::error_code error) {
      if (error) return;
      send_status();
      schedule_status();
    });
  }

  void schedule_drain() {
    drain_timer.expires_after(kDrainPeriod);
    drain_timer.async_wait([this](std::error_code error) {
      if (error) return;
      drain();
      schedule_drain();
    });
  }
};

ClientNetwork::ClientNetwork(ClientOptions options, HapticChannels& channels)
    : impl_(std::make_unique<Impl>(std::move(options), channels, stop_requested_)) {}

ClientNetwork::~ClientNetwork() { stop(); }

WelcomeInfo ClientNetwork::start(double timeout_s) {
  Impl& s = *impl_;
  s.signals.async_wait([this, &s](std::error_code error, int signal) {
    if (error) return;
    spdlog::info("signal {} received: stopping", signal);
    stop_requested_ = true;
    s.connection.stop();
  });
  s.connection.start();
  s.udp.start([&s](wire::Datagram&& datagram, const udp::endpoint&, std::int64_t arrival) {
    s.handle_datagram(datagram, arrival);
  });
  s.schedule_drain();
  s.clock.start();
  s.thread = std::thread([&s] { s.io.run(); });
  std::unique_lock lock(s.welcome_mutex);
  s.welcome_ready.wait_for(lock, std::chrono::duration<double>(timeout_s),
                           [&s] { return s.welcome || !s.refusal.empty(); });
  if (!s.refusal.empty()) throw Error("the server refused to join: " + s.refusal);
  if (!s.welcome) {
    const std::string why = s.connection.join_failure();
    throw Error(fmt::format(
        "cannot join {}:{} (no welcome within {:g} s): {}", s.options.host, s.options.port,
        timeout_s,
        why.empty() ? "no answer (is the address right, and the server running?)" : why));
  }
  return *s.welcome;
}

void ClientNetwork::record_session(const std::filesystem::path& file, const std::string& device,
                                   double force_limit) {
  Impl& s = *impl_;
  auto recorder = std::make_unique<record::SessionRecorder>(file);
  std::promise<void> done;
  asio::post(s.io, [&s, &recorder, &done, &device, force_limit] {
    recorder->config(client_session_config(s.options.user_name, device, force_limit, s.session_id,
                                           s.welcomed, now_ns()));
    s.recorder = std::move(recorder);
    s.channels.tracing = true;
    done.set_value();
  });
  done.get_future().wait();
  spdlog::info("recording to {}", file.string());
}

void ClientNetwork::report_status(const HapticMetrics& metrics, const TimerFloors& floors) {
  Impl& s = *impl_;
  asio::post(s.io, [&s, &metrics, &floors] {
    s.haptic_metrics = &metrics;
    s.floors = &floors;
    s.schedule_status();
  });
}

void ClientNetwork::stop() {
  Impl& s = *impl_;
  if (!s.thread.joinable()) return;
  stop_requested_ = true;
  asio::post(s.io, [&s] {
    s.connection.stop();
    s.drain();
    if (s.recorder) s.recorder->close();
    s.status_timer.cancel();
    s.udp.close();  // no more one-way delays: the final status has the report's figures
    s.send_status();
    if (s.connected) {
      wire::Control control;
      control.mutable_bye()->set_reason("client finished");
      s.connection.send(control);
    }
    auto timer = std::make_shared<asio::steady_timer>(s.io, kGoodbyeGrace);
    timer->async_wait([&s, timer](std::error_code) { s.io.stop(); });
  });
  s.thread.join();
}

nlohmann::json ClientNetwork::report() const {
  const Impl& s = *impl_;
  const wire::RejectionCounters& rejections = s.udp.inspector().counters();
  nlohmann::json out;
  out["datagrams"] = {{"sent", s.udp.sent()},
                      {"received", rejections.accepted() + rejections.rejected()},
                      {"rejected", rejections.rejected()},
                      {"rejected_by_reason", rejections.snapshot()},
                      {"dropped_by_kernel", s.udp.kernel_dropped()}};
  out["ir"] = s.irs.report();
  out["forces_received"] = s.forces_received;
  out["remote_samples_received"] = s.remote_samples;
  s.clock.add_to_report(out);
  out["reconnects"] = s.reconnects;
  out["encrypted"] = s.options.encrypt;
  out["non_finite_events"] = s.non_finite_events;
  return out;
}

}  // namespace cohaptic
