#include "client/client_network.h"

#include <spdlog/spdlog.h>

#include <asio.hpp>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <fstream>
#include <future>
#include <mutex>
#include <thread>

#include "common/sync/clock_offset.h"
#include "proto/record/session_recorder.h"
#include "proto/wire/datagram_codec.h"
#include "proto/wire/frame_codec.h"
#include "proto/wire/ir_convert.h"
#include "proto/wire/session_key.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic {

using asio::ip::tcp;
using asio::ip::udp;

namespace {

std::int64_t now_ns() { return wire::monotonic_now_ns(); }

const char* event_name(HapticEventKind kind) {
  switch (kind) {
    case HapticEventKind::non_finite: return "non-finite force: zero output";
    case HapticEventKind::ir_switched: return "IR switched";
    case HapticEventKind::fading: return "stale IR: fading";
    case HapticEventKind::started_realtime: return "haptic thread running SCHED_FIFO with locked memory";
    case HapticEventKind::realtime_refused: return "SCHED_FIFO or mlockall refused (not permitted): running best effort";
  }
  return "?";
}

}  // namespace

struct ClientNetwork::Impl {
  ClientOptions options;
  HapticChannels& channels;
  std::atomic<bool>& stop_requested;
  wire::SessionKey key;

  asio::io_context io;
  tcp::socket tcp_socket{io};
  udp::socket udp_socket{io};
  udp::endpoint server_udp;
  asio::steady_timer tick_timer{io}, ping_timer{io}, reconnect_timer{io};
  asio::signal_set signals{io, SIGINT, SIGTERM};
  std::array<std::uint8_t, 64 * 1024> tcp_buffer{};
  std::array<std::uint8_t, 2048> udp_buffer{};
  udp::endpoint udp_from;
  std::unique_ptr<wire::FrameReader> reader;
  wire::DatagramInspector inspector;
  wire::HeaderStamp udp_stamp{0, 0}, control_stamp{0, 0};
  std::deque<std::vector<std::uint8_t>> writes;
  ClockOffsetEstimator clock;
  std::thread thread;

  // Welcome hand-off to start().
  std::mutex welcome_mutex;
  std::condition_variable welcome_ready;
  std::optional<WelcomeInfo> welcome;
  std::string refusal;
  bool connected = false;
  bool ever_connected = false;

  // Counters (I/O thread; read after stop()).
  std::uint64_t datagrams_sent = 0, irs_received = 0, ir_bytes = 0, irs_rejected = 0, reconnects = 0, forces_received = 0;
  std::uint64_t remote_samples = 0, events_logged = 0, non_finite_events = 0;
  Histogram one_way_ns{10'000, 100'000};  // server -> client, 10 us bins up to 1 s
  std::int64_t first_ir_ns = 0, last_ir_ns = 0;
  std::unique_ptr<record::SessionRecorder> recorder;  // from record_session() on
  std::optional<WelcomeInfo> welcomed;                 // the last welcome, for the recording
  std::uint64_t session_id = 0;

  Impl(ClientOptions o, HapticChannels& c, std::atomic<bool>& stop)
      : options(std::move(o)),
        channels(c),
        stop_requested(stop),
        key(options.key_file ? wire::load_session_key(*options.key_file) : wire::development_key()),
        inspector(key) {
    if (!options.key_file) spdlog::warn("no --key-file: using the public development key");
    inspector.allow_sender(wire::kServerSender);
    udp_socket.open(udp::v4());
    udp_socket.bind(udp::endpoint(asio::ip::make_address("0.0.0.0"), 0));
    spdlog::info("receiving datagrams on UDP port {}", udp_socket.local_endpoint().port());
  }

  // ---- connection ----

  void connect() {
    std::error_code error;
    tcp_socket.close(error);
    tcp_socket = tcp::socket(io);
    tcp::resolver resolver(io);
    const auto endpoints = resolver.resolve(options.host, std::to_string(options.port), error);
    if (error) {
      spdlog::warn("cannot resolve {}: {}", options.host, error.message());
      schedule_reconnect();
      return;
    }
    asio::async_connect(tcp_socket, endpoints, [this](std::error_code e, const tcp::endpoint&) {
      if (e) {
        schedule_reconnect();
        return;
      }
      tcp_socket.set_option(tcp::no_delay(true));
      reader = std::make_unique<wire::FrameReader>(key);
      writes.clear();
      wire::Control control;
      control.mutable_join()->set_user_name(options.user_name);
      control.mutable_join()->set_udp_port(udp_socket.local_endpoint().port());
      control.mutable_join()->set_requested_slot(options.requested_slot >= 0 ? static_cast<std::uint32_t>(options.requested_slot + 1) : 0);
      send_control(control);
      read_control();
    });
  }

  void schedule_reconnect() {
    if (stop_requested.load()) return;
    reconnect_timer.expires_after(std::chrono::milliseconds(500));
    reconnect_timer.async_wait([this](std::error_code e) {
      if (!e) connect();
    });
  }

  void lost(const std::string& why) {
    if (stop_requested.load()) return;  // our own goodbye
    if (recorder && connected) recorder->event(now_ns(), "lost", why);
    if (connected) {
      spdlog::warn("lost the server ({}); zero force until it is back, reconnecting", why);
      connected = false;
    }
    std::error_code ignored;
    tcp_socket.close(ignored);
    schedule_reconnect();
  }

  void send_control(wire::Control& control) {
    control_stamp.stamp(*control.mutable_header());
    writes.push_back(wire::encode_frame(control, key));
    if (writes.size() == 1) write_next();
  }

  void write_next() {
    asio::async_write(tcp_socket, asio::buffer(writes.front()), [this](std::error_code error, std::size_t) {
      if (error) {
        writes.clear();
        return;  // the read side notices and reconnects
      }
      writes.pop_front();
      if (!writes.empty()) write_next();
    });
  }

  void read_control() {
    tcp_socket.async_read_some(asio::buffer(tcp_buffer), [this](std::error_code error, std::size_t n) {
      if (error) {
        if (error != asio::error::operation_aborted) lost(error == asio::error::eof ? "closed" : error.message());
        return;
      }
      try {
        reader->feed(std::span(tcp_buffer.data(), n));
        while (auto control = reader->next()) handle_control(*control, n);
      } catch (const Error& e) {
        spdlog::error("control channel: {}", e.what());
        lost("protocol error");
        return;
      }
      read_control();
    });
  }

  void handle_control(const wire::Control& control, std::size_t) {
    if (control.has_welcome()) {
      const wire::Welcome& w = control.welcome();
      WelcomeInfo info;
      info.slot = static_cast<int>(w.slot());
      info.scene_name = w.scene_name();
      info.scene_yaml = w.scene_yaml();
      info.protocol = w.protocol() == wire::P0 ? HapticProtocol::p0 : HapticProtocol::p1;
      info.force_limit = w.force_limit();
      info.haptic_rate_hz = w.haptic_rate_hz();
      info.ir_max_age_s = w.ir_max_age_s();
      info.user_count = w.users_size();
      server_udp = udp::endpoint(tcp_socket.remote_endpoint().address(), static_cast<std::uint16_t>(w.server_udp_port()));
      const std::uint64_t session = control.header().session();
      inspector.set_expected_session(session);
      inspector.allow_sender(wire::kServerSender);  // fresh replay window for a new session
      // Sequence numbers keep increasing across sessions: a fresh replay window accepts them.
      udp_stamp.set_session(session);
      udp_stamp.set_sender(wire::sender_of_slot(w.slot()));
      control_stamp.set_session(session);
      control_stamp.set_sender(wire::sender_of_slot(w.slot()));
      clock = ClockOffsetEstimator();
      if (ever_connected) ++reconnects;
      ever_connected = connected = true;
      spdlog::info("joined '{}' as slot {} ({} protocol, force limit {:g} N)", info.scene_name, info.slot,
                   info.protocol == HapticProtocol::p1 ? "P1" : "P0", info.force_limit);
      send_ping();
      session_id = session;
      welcomed = info;
      if (recorder) recorder->event(now_ns(), "joined", fmt::format("session {:016x}, slot {}", session, info.slot));
      std::lock_guard lock(welcome_mutex);
      welcome = info;
      welcome_ready.notify_all();
    } else if (control.has_ir()) {
      receive_ir(control.ir(), control.ByteSizeLong());
    } else if (control.has_event()) {
      spdlog::info("server: {}", control.event().text());
    } else if (control.has_error()) {
      spdlog::error("server refused: {} ({})", control.error().text(), control.error().code());
      std::lock_guard lock(welcome_mutex);
      refusal = control.error().text();
      welcome_ready.notify_all();
    } else if (control.has_bye()) {
      lost("server said goodbye: " + control.bye().reason());
    }
  }

  void receive_ir(const wire::IntermediateRepresentation& message, std::size_t bytes) {
    const std::int64_t arrival = now_ns();
    try {
      auto prepared = std::make_unique<const PreparedIR>(prepare_ir(wire::from_wire(message)));
      if (recorder) recorder->ir(arrival, message);
      channels.ir.back() = IrSlot{std::move(prepared), arrival};
      channels.ir.publish();
      ++irs_received;
      ir_bytes += bytes;
      if (!first_ir_ns) first_ir_ns = arrival;
      last_ir_ns = arrival;
    } catch (const Error& e) {
      ++irs_rejected;
      spdlog::warn("IR rejected: {}", e.what());
    }
  }

  // ---- UDP ----

  void receive_datagram() {
    udp_socket.async_receive_from(asio::buffer(udp_buffer), udp_from, [this](std::error_code error, std::size_t n) {
      if (error) {
        if (error != asio::error::operation_aborted) receive_datagram();
        return;
      }
      const std::int64_t arrival = now_ns();
      if (const std::optional<wire::Datagram> datagram = inspector.inspect(std::span(udp_buffer.data(), n))) {
        if (recorder) recorder->datagram_in(arrival, *datagram);
        handle_datagram(*datagram, arrival);
      }
      receive_datagram();
    });
  }

  void handle_datagram(const wire::Datagram& datagram, std::int64_t arrival) {
    if (clock.valid()) one_way_ns.record(arrival - clock.to_client(datagram.header().sender_time_ns()));
    if (datagram.has_pong()) {
      const wire::ClockPong& pong = datagram.pong();
      clock.add(pong.client_send_ns(), pong.server_receive_ns(), pong.server_send_ns(), arrival);
    } else if (datagram.has_tool()) {
      const wire::ToolSample& sample = datagram.tool();
      RemoteSample remote;
      remote.user = sample.user();
      remote.sample_time_ns = clock.to_client(sample.sample_time_ns());
      remote.arrival_ns = arrival;
      remote.position = wire::from_wire(sample.position());
      remote.valid = sample.valid();
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
    udp_stamp.stamp(*datagram.mutable_header());
    auto bytes = std::make_shared<std::vector<std::uint8_t>>(wire::encode_datagram(datagram, key));
    udp_socket.async_send_to(asio::buffer(*bytes), server_udp, [bytes](std::error_code, std::size_t) {});
    ++datagrams_sent;
  }

  void send_ping() {
    wire::Datagram ping;
    ping.mutable_ping()->set_client_send_ns(now_ns());
    send_datagram(ping);
  }

  // Every millisecond: own samples out, events logged, trace written.
  void drain() {
    while (const auto own = channels.own_samples.pop()) {
      wire::Datagram datagram;
      auto* sample = datagram.mutable_tool();
      sample->set_user(udp_stamp.sender() > 0 ? udp_stamp.sender() - 1 : 0);
      sample->set_sample_time_ns(clock.to_server(own->sample_time_ns));
      *sample->mutable_position() = wire::to_wire(own->valid ? own->position : Eigen::Vector3d::Zero());
      sample->set_valid(own->valid);
      sample->set_buttons(own->buttons);
      send_datagram(datagram);
    }
    while (const auto event = channels.events.pop()) {
      ++events_logged;
      if (recorder) recorder->event(event->time_ns, "haptic", event_name(event->kind));
      if (event->kind == HapticEventKind::non_finite) ++non_finite_events;
      if (event->kind == HapticEventKind::realtime_refused || event->kind == HapticEventKind::non_finite)
        spdlog::warn("haptic: {}", event_name(event->kind));
      else
        spdlog::info("haptic: {}", event_name(event->kind));
    }
    while (const auto tick = channels.trace.pop()) {
      if (!recorder) continue;
      record::HapticTick record;
      record.set_time_ns(tick->time_ns);
      wire::to_wire(tick->own, record.mutable_own());
      for (int r = 0; r < tick->remote_count; ++r) wire::to_wire(tick->remotes[r], record.add_remotes());
      wire::to_wire(tick->force, record.mutable_force());
      wire::to_wire(tick->evaluated, record.mutable_evaluated());
      record.set_ir_epoch(tick->ir_epoch);
      record.set_flags(tick->flags);
      record.set_fade(tick->fade);
      record.set_own_valid(tick->own_valid);
      recorder->tick(record);
    }
    if (recorder) recorder->flush_if_due();
  }

  void tick() {
    tick_timer.expires_after(std::chrono::milliseconds(1));
    tick_timer.async_wait([this](std::error_code error) {
      if (error) return;
      drain();
      tick();
    });
  }

  void pinger() {
    ping_timer.expires_after(std::chrono::milliseconds(100));
    ping_timer.async_wait([this](std::error_code error) {
      if (error) return;
      send_ping();
      pinger();
    });
  }
};

ClientNetwork::ClientNetwork(ClientOptions options, HapticChannels& channels)
    : impl_(std::make_unique<Impl>(std::move(options), channels, stop_requested_)) {}

ClientNetwork::~ClientNetwork() { stop(); }

WelcomeInfo ClientNetwork::start(double timeout_s) {
  Impl& s = *impl_;
  s.signals.async_wait([this](std::error_code error, int signal) {
    if (!error) {
      spdlog::info("signal {} received: stopping", signal);
      stop_requested_ = true;
    }
  });
  s.connect();
  s.receive_datagram();
  s.tick();
  s.pinger();
  s.thread = std::thread([&s] { s.io.run(); });
  std::unique_lock lock(s.welcome_mutex);
  s.welcome_ready.wait_for(lock, std::chrono::duration<double>(timeout_s), [&s] { return s.welcome || !s.refusal.empty(); });
  if (!s.refusal.empty()) throw Error("the server refused to join: " + s.refusal);
  if (!s.welcome)
    throw Error(fmt::format("no welcome from {}:{} within {:g} s (is the server running, with the same key?)",
                            s.options.host, s.options.port, timeout_s));
  return *s.welcome;
}

void ClientNetwork::record_session(const std::filesystem::path& file, const std::string& device, double force_limit) {
  Impl& s = *impl_;
  auto recorder = std::make_unique<record::SessionRecorder>(file);
  std::promise<void> done;
  asio::post(s.io, [&s, &recorder, &done, device, force_limit] {
    record::SessionConfig config;
    config.set_role("client");
    config.set_user(s.options.user_name);
    config.set_device(device);
    config.set_force_limit(force_limit);
    config.set_session(s.session_id);
    config.set_start_time_ns(now_ns());
    if (s.welcomed) {
      config.set_scene_name(s.welcomed->scene_name);
      config.set_scene_yaml(s.welcomed->scene_yaml);
      config.set_slot(static_cast<std::uint32_t>(s.welcomed->slot));
      config.set_protocol(s.welcomed->protocol == HapticProtocol::p1 ? wire::P1 : wire::P0);
    }
    recorder->config(config);
    s.recorder = std::move(recorder);
    s.channels.tracing = true;
    done.set_value();
  });
  done.get_future().wait();
  spdlog::info("recording to {}", file.string());
}

void ClientNetwork::stop() {
  Impl& s = *impl_;
  if (!s.thread.joinable()) return;
  stop_requested_ = true;
  asio::post(s.io, [&s] {
    s.drain();
    if (s.recorder) s.recorder->close();
    if (s.connected) {
      wire::Control control;
      control.mutable_bye()->set_reason("client finished");
      s.send_control(control);
    }
    auto timer = std::make_shared<asio::steady_timer>(s.io, std::chrono::milliseconds(50));
    timer->async_wait([&s, timer](std::error_code) { s.io.stop(); });
  });
  s.thread.join();
}

nlohmann::json ClientNetwork::report() const {
  const Impl& s = *impl_;
  const double ir_span_s = static_cast<double>(s.last_ir_ns - s.first_ir_ns) * 1e-9;
  nlohmann::json out;
  out["datagrams"] = {{"sent", s.datagrams_sent},
                      {"received", s.inspector.counters().accepted() + s.inspector.counters().rejected()},
                      {"rejected", s.inspector.counters().rejected()},
                      {"rejected_by_reason", s.inspector.counters().snapshot()}};
  out["ir"] = {{"received", s.irs_received},
               {"rejected", s.irs_rejected},
               {"bytes", s.ir_bytes},
               {"bytes_per_s", ir_span_s > 0 ? static_cast<double>(s.ir_bytes) / ir_span_s : 0.0}};
  out["forces_received"] = s.forces_received;
  out["remote_samples_received"] = s.remote_samples;
  out["clock"] = {{"offset_ms", static_cast<double>(s.clock.offset_ns()) * 1e-6},
                  {"round_trip_ms", static_cast<double>(s.clock.round_trip_ns()) * 1e-6}};
  out["one_way_delay_ms"] = {{"p50", static_cast<double>(s.one_way_ns.quantile(0.5)) * 1e-6},
                             {"p99", static_cast<double>(s.one_way_ns.quantile(0.99)) * 1e-6},
                             {"samples", s.one_way_ns.count()}};
  out["reconnects"] = s.reconnects;
  out["non_finite_events"] = s.non_finite_events;
  return out;
}

}  // namespace cohaptic
