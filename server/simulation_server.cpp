#include "server/simulation_server.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <asio.hpp>
#include <chrono>
#include <fstream>
#include <optional>
#include <random>
#include <thread>

#include "common/model/compliance_setup.h"
#include "common/model/scene_compliance.h"
#include "common/scene/load_scene.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"
#include "common/util/monotonic_clock.h"
#include "common/util/stopwatch.h"
#include "proto/record/session_recorder.h"
#include "proto/wire/header.h"
#include "proto/wire/session_key.h"
#include "proto/wire/surface_mesh_message.h"
#include "server/connection_handler.h"
#include "server/control_socket.h"
#include "server/display_writer.h"
#include "server/loop_statistics.h"
#include "server/server_recording.h"
#include "server/server_report.h"
#include "server/simulation_loop.h"
#include "server/tool_inputs.h"
#include "view/live_view.h"

namespace cohaptic {
namespace {

/// Time the goodbyes get to leave before the connections close at shutdown.
constexpr std::chrono::milliseconds kGoodbyeGrace{100};

std::uint64_t random_session_id() {
  std::random_device entropy;
  const std::uint64_t id = (static_cast<std::uint64_t>(entropy()) << 32) ^ entropy();
  return id == 0 ? 1 : id;
}

// Everything a joining user is told but its slot and the other users' names.
wire::Welcome welcome_template(const ServeOptions& options, const Model& model,
                               const std::string& scene_yaml) {
  wire::Welcome welcome;
  welcome.set_scene_name(model.scene.name);
  welcome.set_scene_yaml(scene_yaml);
  *welcome.mutable_surface() =
      wire::surface_mesh_message(model.bodies.front());  // the first object's
  welcome.set_protocol(wire_protocol(options));
  welcome.set_force_limit(model.scene.haptic.force_limit_n);
  welcome.set_haptic_rate_hz(model.scene.haptic.rate_hz);
  welcome.set_ir_max_age_s(options.ir_max_age_s);
  for (std::size_t slot = 0; slot < model.scene.tools.size(); ++slot) {
    auto* user = welcome.add_users();
    user->set_slot(static_cast<std::uint32_t>(slot));
    user->set_tool_name(model.scene.tools[slot].name);
    user->set_tool_radius(model.scene.tools[slot].radius);
  }
  return welcome;
}

// The conditions served: the --condition list, or the one the options give.
std::vector<ServedCondition> served_conditions(const ServeOptions& options) {
  if (!options.conditions.empty()) return options.conditions;
  ServedCondition condition;
  condition.name = "session";
  condition.protocol = options.protocol;
  condition.shift_delay_ms = options.shift.delay_ms;
  condition.jitter_ms = options.shift.jitter_ms;
  condition.loss = options.shift.loss;
  condition.step_nodes = options.step_nodes;
  condition.sim_rate_hz = options.sim_rate_hz;
  return {condition};
}

}  // namespace

struct SimulationServer::Impl {
  ServeOptions options;
  std::int64_t start_ns = monotonic_now_ns();  // time zero of the simulation and the report
  std::unique_ptr<Model> model;
  SceneCompliance compliance;
  std::string scene_yaml;
  wire::SessionKey key;
  std::uint64_t session_id = random_session_id();
  std::unique_ptr<record::SessionRecorder> recorder;  // with --record
  std::unique_ptr<ToolInputs> tools;
  LoopStatistics statistics;
  std::unique_ptr<DisplayWriter> display;  // with --display
  std::unique_ptr<view::LiveView> view;    // with --view
  ConditionSwitch conditions;
  std::unique_ptr<SimulationLoop> loop;
  asio::io_context io;
  std::unique_ptr<ConnectionHandler> connections;
  std::unique_ptr<ControlSocket> control;  // with --control
  asio::signal_set signals{io, SIGINT, SIGTERM};
  asio::steady_timer status_timer{io}, duration_timer{io};
  std::atomic<bool> running{true};
  std::thread sim_thread;
  std::optional<std::string>
      failure;  // why the simulation loop ended the session; read after it joined

  explicit Impl(ServeOptions o) : options(std::move(o)), conditions(served_conditions(options)) {}

  void load() {
    Stopwatch watch;
    Scene scene = load_scene(options.scene);
    use_separation_field_cache(scene, options.cache_directory);
    {
      std::ifstream in(options.scene);
      scene_yaml.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    model = std::make_unique<Model>(build_model(scene));
    bool holds_nodes = false;  // under any condition served
    for (const ServedCondition& condition : conditions.conditions())
      holds_nodes = holds_nodes || condition.step_nodes > 0;
    const bool whole_surface =
        holds_nodes || !model->obstacles.empty() || !model->scene.interactions.empty();
    compliance = prepare_scene_compliance(*model, whole_surface, options.cache_directory);
    // The display shows one linear elastic object (single_elastic_body says why it refuses
    // another scene) or one home-spring tissue; the live view shows every body.
    const auto* tissue =
        model->bodies.size() == 1 ? std::get_if<HomeSpringBody>(&model->bodies.front()) : nullptr;
    if (!options.display.empty() && !tissue)
      single_elastic_body(*model);  // refuses another scene, naming it
    if (!options.display.empty())
      display = tissue ? std::make_unique<DisplayWriter>(*model, *tissue, options.display)
                       : std::make_unique<DisplayWriter>(*model, *compliance.per_body.front(),
                                                         options.display);
    tools = std::make_unique<ToolInputs>(model->scene.tools.size());
    spdlog::info("scene '{}' ready in {:.0f} ms: {} user slots", scene.name, watch.elapsed_ms(),
                 tools->size());

    if (options.key_file) {
      key = wire::load_session_key(*options.key_file);
    } else {
      key = wire::development_key();
      spdlog::warn(
          "no --key-file: using the public development key; anyone who knows it can join this "
          "session");
    }
    if (!options.record.empty()) {
      recorder = std::make_unique<record::SessionRecorder>(options.record);
      recorder->config(server_session_config(options, *model, scene_yaml, session_id, start_ns));
      spdlog::info("recording to {}", options.record.string());
    }
    if (options.view) {
      view::LiveViewOptions settings;
      settings.host = options.view_host;
      settings.port = options.view_port;
      settings.token_file = options.view_token_file;
      settings.rate_hz = options.view_rate_hz;
      // The session needs no browser: a view that cannot serve its page is off, said once.
      try {
        view = std::make_unique<view::LiveView>(*model, compliance.per_body, wire_protocol(options),
                                                injected_delays(options), settings, recorder.get());
      } catch (const std::exception& e) {
        spdlog::warn("live view off: {}; the session goes on without it", e.what());
      }
    }
    loop = std::make_unique<SimulationLoop>(*model, compliance.per_body, options, *tools,
                                            statistics, display.get(), view.get(), recorder.get(),
                                            start_ns, &conditions);
  }

  void bind() {
    connections = std::make_unique<ConnectionHandler>(
        io, options, welcome_template(options, *model, scene_yaml), key, session_id,
        model->scene.network.max_participants, *tools, recorder.get());
    spdlog::info("listening on {}:{} (TCP control, UDP samples), protocol {}, session {:016x}",
                 options.host, connections->tcp_port(),
                 options.protocol == ServeProtocol::p1 ? "P1" : "P0", session_id);
    if (options.shift.active())
      spdlog::info("injected shift delay on every link, each direction: {}",
                   options.shift.describe());
    if (!options.encrypt)
      spdlog::warn(
          "--no-encryption: frames and datagrams travel in clear (authenticated, readable by "
          "anyone on the path)");
    if (options.conditions.size() > 1)
      spdlog::info("conditions served: {} (starting with '{}')", condition_list(),
                   options.conditions.front().name);
    if (options.control) {
      control = std::make_unique<ControlSocket>(
          io, *options.control,
          [this](const nlohmann::json& command) { return control_command(command); });
      spdlog::info("control socket at {}", options.control->string());
    }
    if (view) {
      connections->on_client_status(
          [this](int slot, const std::string& user, const wire::ClientStatus& status) {
            view->publish_status(slot, user, status,
                                 static_cast<double>(monotonic_now_ns() - start_ns) * 1e-9);
          });
      if (options.view_token_file)  // the operator has the token: it stays out of the log
        spdlog::info("live view at {} (open it in a browser, adding ?token= and the token in {})",
                     view->url(false), options.view_token_file->string());
      else
        spdlog::info("live view at {} (open it in a browser)", view->url());
    }
  }

  ServerFigures figures() const {
    std::vector<std::pair<double, std::string>> switch_log;
    for (const ConditionSwitch::Switch& made : conditions.history())
      switch_log.emplace_back(static_cast<double>(made.time_ns - start_ns) * 1e-9,
                              conditions.conditions()[static_cast<std::size_t>(made.index)].name);
    return {options,
            model->scene.name,
            model->scene.haptic.min_sim_rate_hz,
            statistics.summary(),
            connections->counters(),
            connections->datagram_counters(),
            conditions.served().switches,
            std::move(switch_log)};
  }

  std::string condition_list() const {
    std::vector<std::string> described;
    for (const ServedCondition& condition : conditions.conditions())
      described.push_back(fmt::format("'{}' ({})", condition.name, condition.describe()));
    return fmt::format("{}", fmt::join(described, ", "));
  }

  // One command of the control socket (control_socket.h), on the I/O thread.
  nlohmann::json control_command(const nlohmann::json& command) {
    if (command.contains("serve")) {
      if (!command["serve"].is_string()) throw Error("\"serve\" takes a condition's name");
      // The simulation takes it at its next step, and hands the links' new delay over with
      // that step's outbox.
      conditions.serve(command["serve"].get<std::string>());
    } else if (command.contains("serve_next")) {
      conditions.serve_next();  // the one after the one served now, whoever switched last
    } else if (!command.contains("status")) {
      throw Error(
          fmt::format("unknown command {} (the commands: {{\"serve\": NAME}}, {{\"serve_next\": "
                      "true}}, {{\"status\": true}})",
                      command.dump()));
    }
    const ConditionSwitch::Served served = conditions.served();
    return {{"served", conditions.conditions()[static_cast<std::size_t>(served.index)].name},
            {"switches", served.switches},
            {"time_s", static_cast<double>(monotonic_now_ns() - start_ns) * 1e-9}};
  }

  void print_status() {
    status_timer.expires_after(
        std::chrono::milliseconds(static_cast<int>(options.status_interval_s * 1000)));
    status_timer.async_wait([this](std::error_code error) {
      if (error) return;
      spdlog::info("{}", status_line(figures(), connections->users(), connections->slots()));
      print_status();
    });
  }

  // The simulation thread: the loop, its outboxes posted to the I/O thread.
  void simulate() {
    failure = loop->run(running, [this](Outbox&& outbox) {
      asio::post(io, [this, outbox = std::move(outbox)]() mutable {
        connections->send(std::move(outbox));
      });
    });
    if (failure) asio::post(io, [this] { shutdown("the server's simulation failed"); });
  }

  // On the I/O thread.
  void shutdown(const std::string& reason) {
    if (!running.exchange(false)) return;
    spdlog::info("shutting down");
    if (control) control->close();
    connections->say_goodbye(reason);
    status_timer.cancel();
    duration_timer.cancel();
    signals.cancel();
    auto timer = std::make_shared<asio::steady_timer>(io, kGoodbyeGrace);
    timer->async_wait([this, timer](std::error_code) {
      connections->close_all("server shut down");
      io.stop();
    });
  }

  void write_report() const {
    nlohmann::json report;
    report["server"] = server_report(figures());
    try {
      if (options.report.has_parent_path())
        std::filesystem::create_directories(options.report.parent_path());
      AtomicFile out(options.report);
      out.write(report.dump(2));
      out.commit();
      spdlog::info("report written to {}", options.report.string());
    } catch (const std::exception& e) {
      spdlog::error("report not written: {}", e.what());
    }
  }
};

SimulationServer::SimulationServer(ServeOptions options)
    : impl_(std::make_unique<Impl>(std::move(options))) {
  validate(impl_->options.shift);
  impl_->load();
  impl_->bind();
}

SimulationServer::~SimulationServer() {
  impl_->running = false;
  if (impl_->sim_thread.joinable()) impl_->sim_thread.join();
  if (impl_->display) impl_->display->stop();
  if (impl_->view) impl_->view->stop();
}

std::uint16_t SimulationServer::tcp_port() const { return impl_->connections->tcp_port(); }
std::uint16_t SimulationServer::udp_port() const { return impl_->connections->udp_port(); }

void SimulationServer::stop() {
  asio::post(impl_->io, [impl = impl_.get()] { impl->shutdown("server shutting down"); });
}

void SimulationServer::run() {
  Impl& s = *impl_;
  s.connections->start();
  s.signals.async_wait([&s](std::error_code error, int signal) {
    if (error) return;
    spdlog::info("signal {} received", signal);
    s.shutdown("server shutting down");
  });
  if (s.options.duration_s > 0) {
    s.duration_timer.expires_after(
        std::chrono::milliseconds(static_cast<long>(s.options.duration_s * 1000)));
    s.duration_timer.async_wait([&s](std::error_code error) {
      if (!error) s.shutdown("server shutting down");
    });
  }
  s.print_status();
  if (s.display) s.display->start();
  if (s.view) s.view->start();
  s.sim_thread = std::thread([&s] { s.simulate(); });
  s.io.run();  // until shutdown() stops it
  s.running = false;
  s.sim_thread.join();
  if (s.display) s.display->stop();
  if (s.view) s.view->stop();
  if (s.recorder) s.recorder->close();
  // Compliance columns computed on demand during the session serve the next one.
  if (s.options.cache_directory)
    save_scene_compliance(*s.model, s.compliance, *s.options.cache_directory);
  if (!s.options.report.empty()) s.write_report();
  if (s.failure) throw Error(*s.failure + "; the session ended");
}

nlohmann::json SimulationServer::report() const { return server_report(impl_->figures()); }

}  // namespace cohaptic
