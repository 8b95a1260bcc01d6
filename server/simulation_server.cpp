#include "server/simulation_server.h"

#include <spdlog/spdlog.h>

#include <asio.hpp>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <fstream>
#include <mutex>
#include <optional>
#include <random>
#include <thread>

#include "common/mesh/write_vtu.h"
#include "common/model/compliance_setup.h"
#include "common/scene/load_scene.h"
#include "common/sim/simulation.h"
#include "common/util/atomic_file.h"
#include "common/util/histogram.h"
#include "common/util/stopwatch.h"
#include "proto/wire/datagram_codec.h"
#include "proto/wire/frame_codec.h"
#include "proto/wire/ir_convert.h"
#include "proto/record/session_recorder.h"
#include "proto/wire/session_key.h"
#include "proto/wire/surface_mesh_message.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic {

using asio::ip::tcp;
using asio::ip::udp;

namespace {

std::int64_t now_ns() { return wire::monotonic_now_ns(); }

wire::Vec3 vec3(const Eigen::Vector3d& v) { return wire::to_wire(v); }

// The statistics of the simulation loop, written by the simulation thread.
struct LoopStats {
  Histogram step_ns{10'000, 100'000};      // 10 us bins up to 1 s
  Histogram ir_build_ns{10'000, 100'000};  // steps that rebuilt the IRs
  std::uint64_t steps = 0, rebuilds = 0, ir_bytes = 0, irs_sent = 0, forces_sent = 0;
  int max_boundary_nodes = 0, max_obstacle_nodes = 0;
  double elapsed_s = 0;
};

}  // namespace

struct SimulationServer::Impl {
  // One TCP connection; becomes a user once it has joined.
  struct Session {
    std::shared_ptr<tcp::socket> socket;
    wire::FrameReader reader;
    std::array<std::uint8_t, 64 * 1024> buffer{};
    std::deque<std::vector<std::uint8_t>> writes;  // queued frames, front in flight
    int slot = -1;
    std::string user_name;
    udp::endpoint udp_endpoint;
    wire::HeaderStamp control_stamp;
    std::unique_ptr<LinkDelay> to_client_udp, to_client_tcp, from_client_udp;
    bool closed = false;
    Session(std::shared_ptr<tcp::socket> s, const wire::SessionKey& key, std::uint64_t session)
        : socket(std::move(s)), reader(key), control_stamp(session, wire::kServerSender) {}
  };

  // The newest tool sample of a slot, shared with the simulation thread.
  struct LatestTool {
    bool joined = false;
    bool valid = false;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    std::int64_t sample_time_ns = 0;   // server clock (as stamped by its client)
    std::int64_t received_ns = 0;
  };

  ServeOptions options;
  std::unique_ptr<Model> model;
  std::unique_ptr<ComplianceColumns> columns;
  std::string scene_yaml;
  wire::SessionKey key;
  std::uint64_t session_id = 0;
  wire::SurfaceMesh surface;

  asio::io_context io;
  tcp::acceptor acceptor{io};
  udp::socket udp_socket{io};
  asio::signal_set signals{io, SIGINT, SIGTERM};
  asio::steady_timer status_timer{io};
  asio::steady_timer duration_timer{io};
  std::array<std::uint8_t, 2048> udp_buffer{};
  udp::endpoint udp_sender;
  std::optional<wire::DatagramInspector> inspector;  // made once the session key is known
  wire::HeaderStamp udp_stamp;
  std::vector<std::shared_ptr<Session>> sessions;           // all connections
  std::vector<std::shared_ptr<Session>> slots;              // joined users by slot
  std::uint64_t datagrams_sent = 0, datagrams_relayed = 0, frames_sent = 0, frames_rejected = 0;
  std::uint64_t dropped_to_clients = 0, dropped_from_clients = 0;  // by the injected loss

  std::mutex tools_mutex;
  std::vector<LatestTool> tools;

  std::unique_ptr<record::SessionRecorder> recorder;  // with --record
  std::atomic<bool> running{true};
  std::thread io_thread, sim_thread, display_thread;

  // Deformation for display: frames from the simulation thread, written by the display thread.
  struct DisplayFrame {
    double time = 0;
    Eigen::Matrix3Xd displacement;  // [m], per display node
  };
  std::vector<int> display_nodes;         // row nodes shown
  std::vector<Triangle> display_triangles;  // in display_nodes numbering
  std::mutex display_mutex;
  std::condition_variable display_ready;
  std::deque<DisplayFrame> display_queue;
  std::vector<std::pair<double, std::string>> display_written;  // for the .pvd index
  double max_displacement = 0;
  mutable std::mutex stats_mutex;
  LoopStats stats;
  std::int64_t start_ns = now_ns();

  explicit Impl(ServeOptions o) : options(std::move(o)), udp_stamp(0, wire::kServerSender) {}

  // ---- set-up ----

  void load() {
    Stopwatch watch;
    const Scene scene = load_scene(options.scene);
    {
      std::ifstream in(options.scene);
      scene_yaml.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    model = std::make_unique<Model>(build_model(scene));
    columns = std::make_unique<ComplianceColumns>(*model->free_factor, model->dofs,
                                                  compliance_row_nodes(*model, options.step_nodes > 0));
    prepare_compliance(*model, *columns, options.cache_directory);
    surface = wire::surface_mesh_message(*model);
    if (!options.display.empty()) {
      // The surface triangles whose nodes all have compliance rows can be shown.
      std::vector<int> local(static_cast<std::size_t>(model->mesh.node_count()), -1);
      for (int node : columns->row_nodes()) {
        local[node] = static_cast<int>(display_nodes.size());
        display_nodes.push_back(node);
      }
      for (const Triangle& tri : model->surface.triangles)
        if (local[tri[0]] >= 0 && local[tri[1]] >= 0 && local[tri[2]] >= 0)
          display_triangles.push_back({local[tri[0]], local[tri[1]], local[tri[2]]});
      std::filesystem::create_directories(options.display);
    }
    tools.resize(model->scene.tools.size());
    slots.resize(model->scene.tools.size());
    spdlog::info("scene '{}' ready in {:.0f} ms: {} user slots", scene.name, watch.elapsed_ms(), slots.size());

    if (options.key_file) {
      key = wire::load_session_key(*options.key_file);
    } else {
      key = wire::development_key();
      spdlog::warn("no --key-file: using the public development key; anyone who knows it can join this session");
    }
    std::random_device entropy;
    session_id = (static_cast<std::uint64_t>(entropy()) << 32) ^ entropy();
    if (session_id == 0) session_id = 1;
    inspector.emplace(key, session_id);
    udp_stamp.set_session(session_id);
    if (!options.record.empty()) {
      recorder = std::make_unique<record::SessionRecorder>(options.record);
      record::SessionConfig config;
      config.set_role("server");
      config.set_scene_name(scene.name);
      config.set_scene_yaml(scene_yaml);
      config.set_options(options.options_text);
      config.set_scene_file(std::filesystem::absolute(options.scene).string());
      config.set_patch_rings(static_cast<std::uint32_t>(model->scene.haptic.patch_rings));
      config.set_ir_f32(options.precision == IrPrecision::f32);
      config.set_session(session_id);
      config.set_protocol(options.protocol == ServeProtocol::p1 ? wire::P1 : wire::P0);
      auto* injected = config.mutable_injected();
      injected->set_shift_delay_ms(options.shift.delay_ms);
      injected->set_jitter_ms(options.shift.jitter_ms);
      injected->set_loss(options.shift.loss);
      injected->set_reorder(options.shift.reorder);
      injected->set_seed(options.shift.seed);
      injected->set_step_nodes(static_cast<std::uint32_t>(options.step_nodes));
      injected->set_sim_rate_hz(options.sim_rate_hz);
      injected->set_condensation(options.naive_condensation ? "naive" : "incremental");
      config.set_start_time_ns(now_ns());
      recorder->config(config);
      spdlog::info("recording to {}", options.record.string());
    }
  }

  void bind() {
    const auto address = asio::ip::make_address(options.host);
    const tcp::endpoint tcp_endpoint(address, options.port);
    acceptor.open(tcp_endpoint.protocol());
    acceptor.set_option(tcp::acceptor::reuse_address(true));
    acceptor.bind(tcp_endpoint);
    acceptor.listen();
    udp_socket.open(udp::v4());
    udp_socket.bind(udp::endpoint(address, acceptor.local_endpoint().port()));
    spdlog::info("listening on {}:{} (TCP control, UDP samples), protocol {}, session {:016x}", options.host,
                 acceptor.local_endpoint().port(), options.protocol == ServeProtocol::p1 ? "P1" : "P0", session_id);
    if (options.shift.active()) spdlog::info("injected shift delay on every link, each direction: {}", options.shift.describe());
  }

  // ---- TCP control ----

  void accept() {
    auto socket = std::make_shared<tcp::socket>(io);
    acceptor.async_accept(*socket, [this, socket](std::error_code error) {
      if (error) {
        if (error != asio::error::operation_aborted) spdlog::warn("accept failed: {}", error.message());
        return;
      }
      socket->set_option(tcp::no_delay(true));
      auto session = std::make_shared<Session>(socket, key, session_id);
      const auto link = [this](bool ordered) { return std::make_unique<LinkDelay>(options.shift, ordered); };
      session->to_client_udp = link(false);
      session->to_client_tcp = link(true);
      session->from_client_udp = link(false);
      sessions.push_back(session);
      read_control(session);
      accept();
    });
  }

  void read_control(const std::shared_ptr<Session>& session) {
    session->socket->async_read_some(asio::buffer(session->buffer), [this, session](std::error_code error, std::size_t n) {
      if (error) {
        close(session, error == asio::error::eof ? "disconnected" : error.message());
        return;
      }
      try {
        session->reader.feed(std::span(session->buffer.data(), n));
        while (auto control = session->reader.next()) handle_control(session, *control);
      } catch (const Error& e) {
        ++frames_rejected;
        spdlog::warn("control connection from {}: {}", peer(session), e.what());
        close(session, "protocol error");
        return;
      }
      if (!session->closed) read_control(session);
    });
  }

  static std::string peer(const std::shared_ptr<Session>& session) {
    std::error_code ignored;
    const auto endpoint = session->socket->remote_endpoint(ignored);
    return ignored ? "?" : endpoint.address().to_string() + ":" + std::to_string(endpoint.port());
  }

  void handle_control(const std::shared_ptr<Session>& session, const wire::Control& control) {
    if (control.has_join()) {
      join(session, control.join());
    } else if (control.has_bye()) {
      close(session, "left: " + control.bye().reason());
    }
  }

  void send_error(const std::shared_ptr<Session>& session, const std::string& code, const std::string& text) {
    wire::Control control;
    auto* error = control.mutable_error();
    error->set_code(code);
    error->set_text(text);
    send_control(session, control);
  }

  void join(const std::shared_ptr<Session>& session, const wire::Join& request) {
    if (session->slot >= 0) return;
    int slot = -1;
    if (request.requested_slot() > 0) {
      const auto wanted = static_cast<int>(request.requested_slot() - 1);
      if (wanted < static_cast<int>(slots.size()) && !slots[wanted]) slot = wanted;
    } else {
      for (int s = 0; s < static_cast<int>(slots.size()) && slot < 0; ++s)
        if (!slots[s]) slot = s;
    }
    if (slot < 0) {
      send_error(session, "session_full", fmt::format("no free user slot (the scene has {} tools)", slots.size()));
      spdlog::warn("{} ('{}') refused: no free slot", peer(session), request.user_name());
      return;
    }
    session->slot = slot;
    session->user_name = request.user_name();
    std::error_code ignored;
    session->udp_endpoint = udp::endpoint(session->socket->remote_endpoint(ignored).address(),
                                          static_cast<std::uint16_t>(request.udp_port()));
    slots[slot] = session;
    inspector->allow_sender(wire::sender_of_slot(static_cast<std::uint32_t>(slot)));
    {
      std::lock_guard lock(tools_mutex);
      tools[slot] = LatestTool{};
      tools[slot].joined = true;
    }

    wire::Control control;
    auto* welcome = control.mutable_welcome();
    welcome->set_slot(static_cast<std::uint32_t>(slot));
    welcome->set_scene_name(model->scene.name);
    welcome->set_scene_yaml(scene_yaml);
    *welcome->mutable_surface() = surface;
    welcome->set_protocol(options.protocol == ServeProtocol::p1 ? wire::P1 : wire::P0);
    welcome->set_force_limit(model->scene.haptic.force_limit_n);
    welcome->set_haptic_rate_hz(model->scene.haptic.rate_hz);
    welcome->set_server_udp_port(udp_socket.local_endpoint().port());
    welcome->set_ir_max_age_s(options.ir_max_age_s);
    for (std::size_t s = 0; s < slots.size(); ++s) {
      auto* user = welcome->add_users();
      user->set_slot(static_cast<std::uint32_t>(s));
      user->set_tool_name(model->scene.tools[s].name);
      user->set_tool_radius(model->scene.tools[s].radius);
      if (slots[s]) user->set_user_name(slots[s]->user_name);
    }
    send_control(session, control);
    spdlog::info("user '{}' joined from {} as slot {} (tool {})", session->user_name, peer(session), slot,
                 model->scene.tools[slot].name);
    broadcast_event("user_joined", fmt::format("{} took tool {}", session->user_name, model->scene.tools[slot].name),
                    record::EventUser{session->user_name, static_cast<std::uint32_t>(slot)});
  }

  void close(const std::shared_ptr<Session>& session, const std::string& why) {
    if (session->closed) return;
    session->closed = true;
    std::error_code ignored;
    session->socket->close(ignored);
    std::erase(sessions, session);
    if (session->slot >= 0 && slots[session->slot] == session) {
      const int slot = session->slot;
      slots[slot].reset();
      // Samples the client sent just before its goodbye may still be in flight: accept and
      // ignore them for a moment rather than count them as hostile.
      auto timer = std::make_shared<asio::steady_timer>(io, std::chrono::milliseconds(500));
      timer->async_wait([this, timer, slot](std::error_code) {
        if (!slots[slot]) inspector->forget_sender(wire::sender_of_slot(static_cast<std::uint32_t>(slot)));
      });
      {
        std::lock_guard lock(tools_mutex);
        tools[session->slot] = LatestTool{};
      }
      spdlog::info("user '{}' (slot {}) left: {}; its tool is released", session->user_name, session->slot, why);
      broadcast_event("user_left", fmt::format("{} left ({})", session->user_name, why),
                      record::EventUser{session->user_name, static_cast<std::uint32_t>(slot)});
    }
  }

  void send_control(const std::shared_ptr<Session>& session, wire::Control& control) {
    if (session->closed) return;
    session->control_stamp.stamp(*control.mutable_header());
    std::vector<std::uint8_t> frame = wire::encode_frame(control, key);
    const std::optional<std::int64_t> delay = session->to_client_tcp->delay_ns(now_ns());
    if (!delay || *delay <= 0) {
      enqueue_write(session, std::move(frame));
      return;
    }
    auto timer = std::make_shared<asio::steady_timer>(io, std::chrono::nanoseconds(*delay));
    timer->async_wait([this, session, timer, frame = std::move(frame)](std::error_code error) mutable {
      if (!error) enqueue_write(session, std::move(frame));
    });
  }

  void enqueue_write(const std::shared_ptr<Session>& session, std::vector<std::uint8_t> frame) {
    if (session->closed) return;
    session->writes.push_back(std::move(frame));
    ++frames_sent;
    if (session->writes.size() == 1) write_next(session);
  }

  void write_next(const std::shared_ptr<Session>& session) {
    asio::async_write(*session->socket, asio::buffer(session->writes.front()), [this, session](std::error_code error, std::size_t) {
      if (error) {
        close(session, error.message());
        return;
      }
      session->writes.pop_front();
      if (!session->writes.empty()) write_next(session);
    });
  }

  void broadcast_event(const std::string& kind, const std::string& text,
                       const std::optional<record::EventUser>& user = std::nullopt) {
    if (recorder) recorder->event(now_ns(), kind, text, user);
    for (const auto& session : slots) {
      if (!session) continue;
      wire::Control control;
      control.mutable_event()->set_kind(kind);
      control.mutable_event()->set_text(text);
      send_control(session, control);
    }
  }

  // ---- UDP ----

  void receive_datagram() {
    udp_socket.async_receive_from(asio::buffer(udp_buffer), udp_sender, [this](std::error_code error, std::size_t n) {
      if (error) {
        if (error != asio::error::operation_aborted) receive_datagram();
        return;
      }
      const std::int64_t arrival = now_ns();
      if (std::optional<wire::Datagram> datagram = inspector->inspect(std::span(udp_buffer.data(), n))) {
        const int slot = static_cast<int>(datagram->header().sender()) - 1;
        const auto& session = slots[static_cast<std::size_t>(slot)];
        const std::optional<std::int64_t> delay = session ? session->from_client_udp->delay_ns(arrival) : std::int64_t{0};
        if (!delay) ++dropped_from_clients;
        if (delay && *delay > 0) {
          auto timer = std::make_shared<asio::steady_timer>(io, std::chrono::nanoseconds(*delay));
          timer->async_wait([this, timer, d = std::move(*datagram), slot](std::error_code e) {
            if (!e) handle_datagram(d, slot, now_ns());
          });
        } else if (delay) {
          handle_datagram(*datagram, slot, arrival);
        }
      }
      receive_datagram();
    });
  }

  void handle_datagram(const wire::Datagram& datagram, int slot, std::int64_t arrival) {
    if (slot < 0 || slot >= static_cast<int>(slots.size()) || !slots[slot]) return;
    if (recorder) recorder->datagram_in(arrival, datagram);
    if (datagram.has_tool()) {
      const wire::ToolSample& sample = datagram.tool();
      if (static_cast<int>(sample.user()) != slot) return;  // a user speaks for its own tool only
      {
        std::lock_guard lock(tools_mutex);
        LatestTool& tool = tools[slot];
        if (sample.sample_time_ns() <= tool.sample_time_ns) return;  // older than what we have
        tool.valid = sample.valid();
        tool.position = wire::from_wire(sample.position());
        tool.sample_time_ns = sample.sample_time_ns();
        tool.received_ns = arrival;
      }
      // Relay to the other users, who play it out against their own clocks.
      for (std::size_t other = 0; other < slots.size(); ++other) {
        if (static_cast<int>(other) == slot || !slots[other]) continue;
        wire::Datagram relay;
        *relay.mutable_tool() = sample;
        send_datagram(slots[other], relay);
        ++datagrams_relayed;
      }
    } else if (datagram.has_ping()) {
      wire::Datagram pong;
      pong.mutable_pong()->set_client_send_ns(datagram.ping().client_send_ns());
      pong.mutable_pong()->set_server_receive_ns(arrival);
      pong.mutable_pong()->set_server_send_ns(now_ns());
      send_datagram(slots[slot], pong);
    }
  }

  void send_datagram(const std::shared_ptr<Session>& session, wire::Datagram& datagram) {
    udp_stamp.stamp(*datagram.mutable_header());
    auto bytes = std::make_shared<std::vector<std::uint8_t>>(wire::encode_datagram(datagram, key));
    const std::optional<std::int64_t> delay = session->to_client_udp->delay_ns(now_ns());
    if (!delay) {  // lost on the injected link
      ++dropped_to_clients;
      return;
    }
    const udp::endpoint to = session->udp_endpoint;
    const auto send = [this, bytes, to] {
      udp_socket.async_send_to(asio::buffer(*bytes), to, [bytes](std::error_code, std::size_t) {});
      ++datagrams_sent;
    };
    if (*delay <= 0) {
      send();
      return;
    }
    auto timer = std::make_shared<asio::steady_timer>(io, std::chrono::nanoseconds(*delay));
    timer->async_wait([timer, send](std::error_code error) {
      if (!error) send();
    });
  }

  // ---- the simulation loop ----

  void simulate() {
    SimulationOptions sim_options;
    sim_options.ir = ir_build_options(model->scene.haptic);
    sim_options.ir.precision = options.precision;
    sim_options.step_delay_nodes = options.step_nodes;
    sim_options.naive_every_step = options.naive_condensation;
    Simulation simulation(*model, *columns, model->scene.tools, sim_options);

    const double rate = options.sim_rate_hz > 0 ? options.sim_rate_hz : 1000.0;
    const auto period = static_cast<std::int64_t>(1e9 / rate);
    const auto timeout = static_cast<std::int64_t>(options.client_timeout_s * 1e9);
    std::int64_t next = now_ns();
    std::int64_t last_keep_alive = 0, last_display = 0;
    while (running.load()) {
      const std::int64_t step_start = now_ns();
      std::vector<LatestTool> latest;
      {
        std::lock_guard lock(tools_mutex);
        latest = tools;
      }
      std::vector<bool> fresh_tools(latest.size(), false);
      for (std::size_t u = 0; u < latest.size(); ++u) {
        fresh_tools[u] = latest[u].joined && latest[u].valid && step_start - latest[u].received_ns < timeout;
        if (fresh_tools[u]) simulation.set_tool(static_cast<int>(u), latest[u].position);
        else simulation.clear_tool(static_cast<int>(u));
      }
      StepReport report;
      try {
        report = simulation.step(static_cast<double>(step_start - start_ns) * 1e-9);
      } catch (const Error& e) {
        spdlog::error("simulation step failed, tools released: {}", e.what());
        for (std::size_t u = 0; u < latest.size(); ++u) simulation.clear_tool(static_cast<int>(u));
        continue;
      }
      std::uint64_t irs = 0;
      if (report.rebuilt && (options.protocol == ServeProtocol::p1 || recorder)) {
        for (std::size_t u = 0; u < latest.size(); ++u)
          if (const auto prepared = simulation.ir(static_cast<int>(u))) {
            auto control = std::make_shared<wire::Control>();
            *control->mutable_ir() = wire::to_wire(prepared->ir);
            if (recorder) recorder->ir(step_start, control->ir());
            if (options.protocol != ServeProtocol::p1) continue;
            ++irs;
            asio::post(io, [this, u, control] {
              if (slots[u]) send_control(slots[u], *control);
            });
          }
      }
      // P1: the IRs stand as long as the server says so (every 10 ms).
      if (options.protocol == ServeProtocol::p1 && step_start - last_keep_alive >= 10'000'000) {
        last_keep_alive = step_start;
        for (std::size_t u = 0; u < latest.size(); ++u)
          if (const auto prepared = simulation.ir(static_cast<int>(u))) {
            auto datagram = std::make_shared<wire::Datagram>();
            datagram->mutable_keep_alive()->set_user(static_cast<std::uint32_t>(u));
            datagram->mutable_keep_alive()->set_ir_epoch(prepared->ir.epoch);
            datagram->mutable_keep_alive()->set_simulation_time(prepared->ir.simulation_time);
            asio::post(io, [this, u, datagram] {
              if (slots[u]) send_datagram(slots[u], *datagram);
            });
          }
      }
      std::uint64_t forces = 0;
      std::vector<record::ServerForce> forces_this_step;
      if (options.protocol == ServeProtocol::p0) {
        for (std::size_t u = 0; u < latest.size(); ++u) {
          if (!simulation.ir(static_cast<int>(u))) continue;
          const ForceSample force = simulation.force(static_cast<int>(u));
          auto datagram = std::make_shared<wire::Datagram>();
          auto* sample = datagram->mutable_force();
          sample->set_user(static_cast<std::uint32_t>(u));
          *sample->mutable_force() = vec3(force.force);
          sample->set_tool_time_ns(latest[u].sample_time_ns);
          sample->set_ir_epoch(simulation.ir(static_cast<int>(u))->ir.epoch);
          sample->set_flags(force.flags);
          if (recorder) {
            record::ServerForce recorded;
            recorded.set_slot(static_cast<std::uint32_t>(u));
            wire::to_wire(force.force, recorded.mutable_force());
            recorded.set_ir_epoch(sample->ir_epoch());
            recorded.set_flags(force.flags);
            forces_this_step.push_back(recorded);
          }
          asio::post(io, [this, u, datagram] {
            if (slots[u]) send_datagram(slots[u], *datagram);
          });
          ++forces;
        }
      }
      bool display_frame = false;
      if (!options.display.empty() && step_start - last_display >= static_cast<std::int64_t>(1e9 / options.display_rate_hz)) {
        last_display = step_start;
        display_frame = true;
        DisplayFrame frame{static_cast<double>(step_start - start_ns) * 1e-9, simulation.displacement_of(display_nodes)};
        max_displacement = std::max(max_displacement, frame.displacement.colwise().norm().maxCoeff());
        std::lock_guard lock(display_mutex);
        if (display_queue.size() < 16) display_queue.push_back(std::move(frame));  // never hold the loop up
        display_ready.notify_one();
      }
      if (recorder) {
        record::SimulationStep step;
        step.set_time_ns(step_start);
        step.set_simulation_time(static_cast<double>(step_start - start_ns) * 1e-9);
        for (std::size_t u = 0; u < latest.size(); ++u) {
          auto* tool = step.add_tools();
          tool->set_slot(static_cast<std::uint32_t>(u));
          tool->set_known(fresh_tools[u]);
          wire::to_wire(latest[u].position, tool->mutable_position());
          tool->set_sample_time_ns(latest[u].sample_time_ns);
        }
        step.set_rebuilt(report.rebuilt);
        for (std::size_t u = 0; u < latest.size(); ++u)
          if (simulation.pressing(static_cast<int>(u))) step.add_pressing_slots(static_cast<std::uint32_t>(u));
        step.set_display_frame(display_frame);
        step.set_boundary_nodes(static_cast<std::uint32_t>(report.boundary_nodes));
        for (const record::ServerForce& force : forces_this_step) *step.add_forces() = force;
        recorder->step(step);
        recorder->flush_if_due();
      }
      const std::int64_t step_end = now_ns();
      {
        std::lock_guard lock(stats_mutex);
        stats.step_ns.record(step_end - step_start);
        if (report.recomputed) stats.ir_build_ns.record(static_cast<std::int64_t>(report.rebuild_ms * 1e6));
        if (report.rebuilt) {
          ++stats.rebuilds;
          stats.ir_bytes += report.ir_bytes;
        }
        ++stats.steps;
        stats.forces_sent += forces;
        stats.irs_sent += irs;
        stats.max_boundary_nodes = std::max(stats.max_boundary_nodes, report.boundary_nodes);
        stats.max_obstacle_nodes = std::max(stats.max_obstacle_nodes, report.obstacle_nodes);
        stats.elapsed_s = static_cast<double>(step_end - start_ns) * 1e-9;
      }
      next += period;
      if (next < step_end) next = step_end;  // behind: no catch-up burst
      std::this_thread::sleep_for(std::chrono::nanoseconds(next - step_end));
    }
  }

  // ---- deformation for display ----

  void write_display_frames() {
    const double unit = model->scene.metres_per_unit;
    Eigen::Matrix3Xd rest(3, static_cast<Eigen::Index>(display_nodes.size()));
    std::vector<std::int64_t> tags;
    for (std::size_t i = 0; i < display_nodes.size(); ++i) {
      rest.col(static_cast<Eigen::Index>(i)) = model->mesh.nodes.col(display_nodes[i]) / unit;
      tags.push_back(model->mesh.node_tags[display_nodes[i]]);
    }
    for (;;) {
      DisplayFrame frame;
      {
        std::unique_lock lock(display_mutex);
        display_ready.wait(lock, [this] { return !display_queue.empty() || !running.load(); });
        if (display_queue.empty()) break;
        frame = std::move(display_queue.front());
        display_queue.pop_front();
      }
      const std::string name = fmt::format("surface-{:06d}.vtu", display_written.size());
      try {
        write_surface_vtu(options.display / name, rest, display_triangles, tags,
                          {{"displacement", Eigen::MatrixXd(frame.displacement / unit)}});
        display_written.emplace_back(frame.time, name);
      } catch (const Error& e) {
        spdlog::warn("display frame not written: {}", e.what());
      }
    }
    // The ParaView collection: open surface.pvd to play the deformation over time.
    try {
      AtomicFile index(options.display / "surface.pvd");
      index.write("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n");
      for (const auto& [time, name] : display_written)
        index.print("    <DataSet timestep=\"{:.6f}\" file=\"{}\"/>\n", time, name);
      index.write("  </Collection>\n</VTKFile>\n");
      index.commit();
      spdlog::info("{} display frames in {} (open surface.pvd in ParaView; lengths in {})", display_written.size(),
                   options.display.string(), model->scene.units);
    } catch (const Error& e) {
      spdlog::warn("display index not written: {}", e.what());
    }
  }

  // ---- status, shutdown, report ----

  void print_status() {
    status_timer.expires_after(std::chrono::milliseconds(static_cast<int>(options.status_interval_s * 1000)));
    status_timer.async_wait([this](std::error_code error) {
      if (error) return;
      int users = 0;
      for (const auto& s : slots) users += s != nullptr;
      std::lock_guard lock(stats_mutex);
      spdlog::info("t {:.0f} s | users {}/{} | sim {:.0f} Hz, step p99 {:.2f} ms | |B| max {} | IRs {} | datagrams in {} "
                   "(rejected {}), out {}",
                   stats.elapsed_s, users, slots.size(), stats.elapsed_s > 0 ? static_cast<double>(stats.steps) / stats.elapsed_s : 0.0,
                   static_cast<double>(stats.step_ns.quantile(0.99)) * 1e-6, stats.max_boundary_nodes, stats.rebuilds,
                   inspector->counters().accepted(), inspector->counters().rejected(), datagrams_sent);
      print_status();
    });
  }

  void shutdown() {
    if (!running.exchange(false)) return;
    spdlog::info("shutting down");
    for (const auto& session : slots)
      if (session) {
        wire::Control control;
        control.mutable_bye()->set_reason("server shutting down");
        send_control(session, control);
      }
    std::error_code ignored;
    acceptor.close(ignored);
    status_timer.cancel();
    duration_timer.cancel();
    signals.cancel();
    // Give the goodbyes a moment to leave, then stop the I/O.
    auto timer = std::make_shared<asio::steady_timer>(io, std::chrono::milliseconds(100));
    timer->async_wait([this, timer](std::error_code) {
      std::error_code e;
      udp_socket.close(e);
      for (const auto& session : std::vector(sessions)) close(session, "server shut down");
      io.stop();
    });
  }

  nlohmann::json make_report() const {
    std::lock_guard lock(stats_mutex);
    nlohmann::json server;
    server["scene"] = model->scene.name;
    server["protocol"] = options.protocol == ServeProtocol::p1 ? "P1" : "P0";
    server["sim_rate_hz"] = stats.elapsed_s > 0 ? static_cast<double>(stats.steps) / stats.elapsed_s : 0.0;
    server["steps"] = stats.steps;
    server["step_ms"] = {{"p50", static_cast<double>(stats.step_ns.quantile(0.5)) * 1e-6},
                         {"p99", static_cast<double>(stats.step_ns.quantile(0.99)) * 1e-6},
                         {"max", static_cast<double>(stats.step_ns.max()) * 1e-6}};
    server["ir_build_ms"] = {{"p50", static_cast<double>(stats.ir_build_ns.quantile(0.5)) * 1e-6},
                             {"p99", static_cast<double>(stats.ir_build_ns.quantile(0.99)) * 1e-6},
                             {"count", stats.ir_build_ns.count()}};
    server["irs_sent"] = stats.irs_sent;
    server["ir_bytes_sent"] = stats.ir_bytes;
    server["boundary_nodes"] = {{"max", stats.max_boundary_nodes}, {"obstacle_max", stats.max_obstacle_nodes}};
    server["forces_sent"] = stats.forces_sent;
    server["max_surface_displacement_mm"] = max_displacement * 1e3;
    server["datagrams"] = {{"received", inspector->counters().accepted() + inspector->counters().rejected()},
                           {"accepted", inspector->counters().accepted()},
                           {"rejected", inspector->counters().rejected()},
                           {"rejected_by_reason", inspector->counters().snapshot()},
                           {"sent", datagrams_sent},
                           {"relayed", datagrams_relayed}};
    server["control_frames"] = {{"sent", frames_sent}, {"rejected", frames_rejected}};
    server["injected"] = {{"shift_delay_ms", options.shift.delay_ms},
                          {"jitter_ms", options.shift.jitter_ms},
                          {"loss", options.shift.loss},
                          {"reorder", options.shift.reorder},
                          {"seed", options.shift.seed},
                          {"step_nodes", options.step_nodes},
                          {"sim_rate_hz", options.sim_rate_hz},
                          {"condensation", options.naive_condensation ? "naive" : "incremental"},
                          {"datagrams_dropped_to_clients", dropped_to_clients},
                          {"datagrams_dropped_from_clients", dropped_from_clients}};
    server["elapsed_s"] = stats.elapsed_s;
    return server;
  }
};

SimulationServer::SimulationServer(ServeOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {
  validate(impl_->options.shift);
  impl_->load();
  impl_->bind();
}

SimulationServer::~SimulationServer() {
  stop();
  impl_->running = false;
  impl_->display_ready.notify_all();
  if (impl_->display_thread.joinable()) impl_->display_thread.join();
  if (impl_->sim_thread.joinable()) impl_->sim_thread.join();
  if (impl_->io_thread.joinable()) impl_->io_thread.join();
}

std::uint16_t SimulationServer::tcp_port() const { return impl_->acceptor.local_endpoint().port(); }
std::uint16_t SimulationServer::udp_port() const { return impl_->udp_socket.local_endpoint().port(); }

void SimulationServer::stop() {
  asio::post(impl_->io, [impl = impl_.get()] { impl->shutdown(); });
}

void SimulationServer::run() {
  Impl& s = *impl_;
  s.accept();
  s.receive_datagram();
  s.signals.async_wait([&s](std::error_code error, int signal) {
    if (!error) {
      spdlog::info("signal {} received", signal);
      s.shutdown();
    }
  });
  if (s.options.duration_s > 0) {
    s.duration_timer.expires_after(std::chrono::milliseconds(static_cast<long>(s.options.duration_s * 1000)));
    s.duration_timer.async_wait([&s](std::error_code error) {
      if (!error) s.shutdown();
    });
  }
  s.print_status();
  s.sim_thread = std::thread([&s] { s.simulate(); });
  if (!s.options.display.empty()) s.display_thread = std::thread([&s] { s.write_display_frames(); });
  s.io_thread = std::thread([&s] { s.io.run(); });
  s.io_thread.join();
  s.running = false;
  s.sim_thread.join();
  if (s.display_thread.joinable()) {
    s.display_ready.notify_all();
    s.display_thread.join();
  }
  if (s.recorder) s.recorder->close();
  // Compliance columns computed on demand during the session serve the next one.
  if (s.options.cache_directory && s.model->scene.object.compliance.disk_cache)
    save_compliance(*s.model, *s.columns, *s.options.cache_directory);
  if (!s.options.report.empty()) {
    nlohmann::json report;
    report["server"] = s.make_report();
    try {
      if (s.options.report.has_parent_path()) std::filesystem::create_directories(s.options.report.parent_path());
      AtomicFile out(s.options.report);
      out.write(report.dump(2));
      out.commit();
      spdlog::info("report written to {}", s.options.report.string());
    } catch (const std::exception& e) {
      spdlog::error("report not written: {}", e.what());
    }
  }
}

nlohmann::json SimulationServer::report() const { return impl_->make_report(); }

}  // namespace cohaptic
