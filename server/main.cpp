// cohaptic-server: the networked simulation server.
//   cohaptic-server --scene FILE --listen HOST:PORT [...]   serve a scene to haptic clients
// The offline tools (probe, replay, study, ...) are cohaptic-lab's. Every option:
// docs/server.md.
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <string>
#include <vector>

#include "common/model/compliance_setup.h"
#include "common/util/host_port.h"
#include "common/util/blas_threads.h"
#include "common/util/error.h"
#include "common/util/keep_freed_memory.h"
#include "common/util/log_to_stderr.h"
#include "server/simulation_server.h"

int main(int argc, char** argv) {
  cohaptic::log_to_stderr();
  cohaptic::keep_freed_memory();

  CLI::App app{
      "cohaptic-server: FEM simulation server for networked haptic collaboration. Serves a scene "
      "to "
      "haptic clients (--scene, --listen). The offline tools are cohaptic-lab's."};
  std::string log_level = "info";
  app.add_option("--log-level", log_level,
                 "Log verbosity on stderr: trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();

  // Serving.
  cohaptic::ServeOptions serve;
  std::string listen = "127.0.0.1:7400", protocol = "P1", condensation = "incremental",
              serve_precision = "f64", ir_form = "rows";
  std::string serve_cache_dir = cohaptic::default_cache_directory().string();
  bool serve_no_disk_cache = false;
  app.add_option("--scene", serve.scene, "Scene file (YAML) to serve")->check(CLI::ExistingFile);
  app.add_option("--listen", listen,
                 "HOST:PORT for TCP control and UDP samples (port 0: any free port)")
      ->capture_default_str();
  app.add_option("--protocol", protocol,
                 "P0: the server computes the force, the client holds it; P1: the server "
                 "sends the IR, the client computes the force at its haptic rate")
      ->check(CLI::IsMember({"P0", "P1"}))
      ->capture_default_str();
  app.add_option(
         "--key-file", serve.key_file,
         "Session key file (cohaptic-lab keygen; mode 0600); without it the public development key")
      ->check(CLI::ExistingFile);
  bool no_encryption = false;
  app.add_flag("--no-encryption", no_encryption,
               "Send frames and datagrams in clear (still authenticated), and accept clients that "
               "do; for debugging "
               "with a packet capture");
  app.add_option("--shift-delay-ms", serve.shift.delay_ms,
                 "Injected one-way delay on every link, each direction [ms]")
      ->capture_default_str();
  app.add_option("--jitter-ms", serve.shift.jitter_ms,
                 "Injected jitter: extra delay drawn from U(0, J) ms")
      ->capture_default_str();
  app.add_option("--loss", serve.shift.loss, "Injected loss probability of UDP datagrams")
      ->capture_default_str();
  app.add_option("--reorder", serve.shift.reorder,
                 "Probability that a datagram is held back past later ones")
      ->capture_default_str();
  app.add_option("--seed", serve.shift.seed, "Seed of the injected delays")->capture_default_str();
  app.add_option("--step-nodes", serve.step_nodes,
                 "Step delay, the natural kind: hold this many surface nodes near the contact (the "
                 "paper's T150/T300)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--sim-rate-hz", serve.sim_rate_hz,
                 "Step delay, the capped kind: simulation loop rate (0: up to 1 kHz)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  std::vector<std::string> condition_texts;
  app.add_option(
         "--condition", condition_texts,
         "A condition the session switches between while it runs (repeat it; the first is served "
         "at the "
         "start): NAME:protocol=P0|P1,shift_ms=S,jitter_ms=J,loss=L,step_nodes=N,sim_rate_hz=R "
         "(unset: P1 "
         "and 0); instead of --protocol, --shift-delay-ms, --jitter-ms, --loss, --step-nodes, "
         "--sim-rate-hz")
      ->take_all();
  int switch_button = -1;
  app.add_option("--switch-button", switch_button,
                 "With --condition: a press of this device button (0, 1, ...: any user's) serves "
                 "the next condition")
      ->check(CLI::Range(0, 31));
  std::string control_path;
  app.add_option("--control", control_path,
                 "Listen for control commands (switch the condition served: {\"serve\": NAME}) on "
                 "this Unix socket");
  app.add_option("--condensation", condensation,
                 "incremental (M~ updated when a set changes) or naive (M~ computed from scratch "
                 "every step, as the "
                 "paper's conventional loop; a new IR is still sent only when a set changes)")
      ->check(CLI::IsMember({"incremental", "naive"}))
      ->capture_default_str();
  app.add_option("--ir-form", ir_form,
                 "How condensed FEM IRs travel: rows (the compliance rows of the nodes a client "
                 "does not hold yet; it "
                 "condenses them itself) or m_tilde (M~ whole)")
      ->check(CLI::IsMember({"rows", "m_tilde"}))
      ->capture_default_str();
  app.add_option("--ir-precision", serve_precision,
                 "Storage of M~ and u_B in the IRs sent: f64 or f32")
      ->check(CLI::IsMember({"f64", "f32"}))
      ->capture_default_str();
  app.add_option("--duration", serve.duration_s, "Stop after S seconds (0: until SIGINT/SIGTERM)")
      ->capture_default_str();
  app.add_option("--report", serve.report, "Write a JSON report here at exit");
  app.add_option("--record", serve.record,
                 "Record the session here (MCAP: configuration, datagrams, every simulation step, "
                 "IRs, forces, events)");
  app.add_option("--client-timeout", serve.client_timeout_s,
                 "Release a tool after S seconds without samples")
      ->capture_default_str();
  app.add_option("--display", serve.display,
                 "Write the deformed surface here (surface-*.vtu and surface.pvd, for ParaView) at "
                 "--display-rate-hz");
  app.add_option("--display-rate-hz", serve.display_rate_hz, "Frames per second of --display")
      ->check(CLI::Range(0.1, 100.0))
      ->capture_default_str();
  std::string view_address;
  app.add_option("--view", view_address,
                 "Serve the live view in a browser at HOST:PORT (HTTP page and WebSocket data; off "
                 "loopback a token "
                 "is required, see --view-token-file)");
  app.add_option("--view-rate-hz", serve.view_rate_hz, "Frames per second of the live view")
      ->check(CLI::Range(1.0, 60.0))
      ->capture_default_str();
  app.add_option("--view-token-file", serve.view_token_file,
                 "The live view's access token (first line; at least 16 letters, digits, - or _). "
                 "Without it: none on "
                 "loopback, a random one (in the printed address) elsewhere")
      ->check(CLI::ExistingFile);
  app.add_option("--cache-dir", serve_cache_dir, "Directory of the on-disk compliance cache")
      ->capture_default_str();
  app.add_flag("--no-disk-cache", serve_no_disk_cache,
               "Neither read nor write the on-disk compliance cache");

  // The offline tools are cohaptic-lab subcommands: naming one here fails, with the cohaptic-lab
  // spelling. Parsing stops at the first argument it does not know, which is then checked.
  app.prefix_command();

  CLI11_PARSE(app, argc, argv);
  if (const std::vector<std::string> rest = app.remaining(); !rest.empty()) {
    for (const char* tool :
         {"probe", "replay", "study", "tradeoff", "stability", "summarize", "keygen"})
      if (rest.front() == tool) {
        fmt::print(
            stderr,
            "cohaptic-server {0}: {0} is a cohaptic-lab command: run `cohaptic-lab {0} ...`\n",
            tool);
        return 2;
      }
    return app.exit(CLI::ExtrasError(rest));
  }
  spdlog::set_level(spdlog::level::from_str(log_level));
  cohaptic::use_single_blas_thread();

  try {
    if (serve.scene.empty()) {
      fmt::print(stderr, "cohaptic-server: --scene is required (see --help)\n");
      return 2;
    }
    if (const std::string problem = cohaptic::parse_host_port(listen, serve.host, serve.port, true);
        !problem.empty()) {
      fmt::print(stderr, "cohaptic-server: --listen: {}\n", problem);
      return 2;
    }
    serve.encrypt = !no_encryption;
    if (!view_address.empty()) {
      if (const std::string problem =
              cohaptic::parse_host_port(view_address, serve.view_host, serve.view_port, true);
          !problem.empty()) {
        fmt::print(stderr, "cohaptic-server: --view: {}\n", problem);
        return 2;
      }
      serve.view = true;
    }
    serve.protocol = protocol == "P0" ? cohaptic::ServeProtocol::p0 : cohaptic::ServeProtocol::p1;
    if (!condition_texts.empty()) {
      for (const char* option : {"--protocol", "--shift-delay-ms", "--jitter-ms", "--loss",
                                 "--step-nodes", "--sim-rate-hz"})
        if (app.count(option) > 0) {
          fmt::print(
              stderr,
              "cohaptic-server: {} and --condition: give the setting in each --condition instead\n",
              option);
          return 2;
        }
      for (const std::string& text : condition_texts)
        serve.conditions.push_back(cohaptic::parse_served_condition(text));
      const cohaptic::ServedCondition& first = serve.conditions.front();
      serve.protocol = first.protocol;
      serve.shift = first.link_delay(serve.shift);
      serve.step_nodes = first.step_nodes;
      serve.sim_rate_hz = first.sim_rate_hz;
    }
    if (!control_path.empty()) serve.control = control_path;
    if (switch_button >= 0) {
      if (serve.conditions.size() < 2) {
        fmt::print(stderr,
                   "cohaptic-server: --switch-button switches between conditions: give two or more "
                   "--condition\n");
        return 2;
      }
      serve.switch_button = switch_button;
    }
    serve.naive_condensation = condensation == "naive";
    serve.compliance_rows = ir_form == "rows";
    serve.precision =
        serve_precision == "f32" ? cohaptic::IrPrecision::f32 : cohaptic::IrPrecision::f64;
    if (!serve_no_disk_cache) serve.cache_directory = serve_cache_dir;
    serve.options_text = app.config_to_str(true, false);
    cohaptic::SimulationServer server(serve);
    server.run();
    return 0;
  } catch (const cohaptic::Error& e) {
    spdlog::error("{}", e.what());
    return 1;
  } catch (const std::exception& e) {
    spdlog::error("unexpected failure: {}", e.what());
    return 1;
  }
}
