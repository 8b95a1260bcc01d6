// cohaptic-server: the simulation server.
//   cohaptic-server --scene FILE --listen HOST:PORT [...]   serve a scene to haptic clients
//   cohaptic-server probe ...                               static forces at tool positions
//   cohaptic-server replay FILE [--summary|--verify|--export-csv DIR]  a recorded session
//   cohaptic-server study FILE --out DIR                    a lab study, trial by trial
//   cohaptic-server tradeoff --scene F --motion M... --out D speed against accuracy, per setting
//   cohaptic-server stability --out DIR                     the stability map of a virtual wall
//   cohaptic-server keygen FILE                             a new session key file
//   cohaptic-server summarize ...                           merge reports, judge a session
// See README.md for every option.
#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>

#include "common/model/compliance_setup.h"
#include "common/net/host_port.h"
#include "common/util/blas_threads.h"
#include "common/util/error.h"
#include "proto/wire/session_key.h"
#include "server/probe.h"
#include "server/replay.h"
#include "server/stability.h"
#include "server/study.h"
#include "server/tradeoff.h"
#include "server/session_summary.h"
#include "server/simulation_server.h"

namespace {

// Parses "x,y,z" (three finite numbers separated by commas).
std::string parse_point(const std::string& text, Eigen::Vector3d& point) {
  double v[3];
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3 || !std::isfinite(v[0]) ||
      !std::isfinite(v[1]) || !std::isfinite(v[2]))
    return "expected x,y,z (three numbers separated by commas), got '" + text + "'";
  point = {v[0], v[1], v[2]};
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  auto logger = spdlog::stderr_color_mt("cohaptic");
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");

  CLI::App app{"cohaptic-server: FEM simulation server for networked haptic collaboration. Serves a scene to "
               "haptic clients (--scene, --listen), or runs a subcommand."};
  app.require_subcommand(0, 1);
  app.fallthrough();  // --log-level may follow a subcommand
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "Log verbosity on stderr: trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();

  // Serving.
  cohaptic::ServeOptions serve;
  std::string listen = "127.0.0.1:7400", protocol = "P1", condensation = "incremental", serve_precision = "f64";
  std::string serve_cache_dir = cohaptic::default_cache_directory().string();
  bool serve_no_disk_cache = false;
  app.add_option("--scene", serve.scene, "Scene file (YAML) to serve")->check(CLI::ExistingFile);
  app.add_option("--listen", listen, "HOST:PORT for TCP control and UDP samples (port 0: any free port)")->capture_default_str();
  app.add_option("--protocol", protocol, "P0: the server computes the force, the client holds it; P1: the server "
                                         "sends the IR, the client computes the force at its haptic rate")
      ->check(CLI::IsMember({"P0", "P1"}))
      ->capture_default_str();
  app.add_option("--key-file", serve.key_file, "Session key (64 hex characters); without it the public development key")
      ->check(CLI::ExistingFile);
  app.add_option("--shift-delay-ms", serve.shift.delay_ms, "Injected one-way delay on every link, each direction [ms]")
      ->capture_default_str();
  app.add_option("--jitter-ms", serve.shift.jitter_ms, "Injected jitter: extra delay drawn from U(0, J) ms")->capture_default_str();
  app.add_option("--loss", serve.shift.loss, "Injected loss probability of UDP datagrams")->capture_default_str();
  app.add_option("--reorder", serve.shift.reorder, "Probability that a datagram is held back past later ones")->capture_default_str();
  app.add_option("--seed", serve.shift.seed, "Seed of the injected delays")->capture_default_str();
  app.add_option("--step-nodes", serve.step_nodes,
                 "Step delay, the natural kind: hold this many surface nodes near the contact (the paper's T150/T300)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--sim-rate-hz", serve.sim_rate_hz, "Step delay, the capped kind: simulation loop rate (0: up to 1 kHz)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--condensation", condensation,
                 "incremental (M~ updated when a set changes) or naive (M~ computed from scratch every step, as the "
                 "paper's conventional loop; a new IR is still sent only when a set changes)")
      ->check(CLI::IsMember({"incremental", "naive"}))
      ->capture_default_str();
  app.add_option("--ir-precision", serve_precision, "Storage of M~ and u_B in the IRs sent: f64 or f32")
      ->check(CLI::IsMember({"f64", "f32"}))
      ->capture_default_str();
  app.add_option("--duration", serve.duration_s, "Stop after S seconds (0: until SIGINT/SIGTERM)")->capture_default_str();
  app.add_option("--report", serve.report, "Write a JSON report here at exit");
  app.add_option("--record", serve.record,
                 "Record the session here (MCAP: configuration, datagrams, every simulation step, IRs, forces, events)");
  app.add_option("--client-timeout", serve.client_timeout_s, "Release a tool after S seconds without samples")->capture_default_str();
  app.add_option("--display", serve.display,
                 "Write the deformed surface here (surface-*.vtu and surface.pvd, for ParaView) at --display-rate-hz");
  app.add_option("--display-rate-hz", serve.display_rate_hz, "Frames per second of --display")
      ->check(CLI::Range(0.1, 100.0))
      ->capture_default_str();
  app.add_option("--cache-dir", serve_cache_dir, "Directory of the on-disk compliance cache")->capture_default_str();
  app.add_flag("--no-disk-cache", serve_no_disk_cache, "Neither read nor write the on-disk compliance cache");

  // probe
  cohaptic::ProbeOptions probe;
  std::vector<std::string> tool_texts;
  std::string cache_dir = cohaptic::default_cache_directory().string();
  bool no_disk_cache = false;
  CLI::App* probe_cmd = app.add_subcommand(
      "probe",
      "Static reaction force at tool positions pressed into the scene's object, through the intermediate "
      "representation (condensed M~) and the haptic force evaluator, or the full FEM solve. Prints a table, "
      "or JSON with --json.");
  probe_cmd->add_option("--scene", probe.scene, "Scene file (YAML)")->required()->check(CLI::ExistingFile);
  probe_cmd
      ->add_option("--tool", tool_texts,
                   "Tool position x,y,z in the scene's units; repeat for several tools pressing at once. "
                   "Tool k takes the shape of the scene's k-th tool (the last one if there are fewer)")
      ->required();
  probe_cmd->add_flag("--separately", probe.separately,
                      "Press each tool alone (one solve per tool) instead of all tools at once");
  std::string contact_model, precision = "f64";
  probe_cmd->add_option("--boundary-nodes", probe.boundary_nodes,
                        "Hold the N surface nodes nearest the tools at rest (the paper's step-delay T150/T300 sets)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  probe_cmd->add_option("--contact-model", contact_model,
                        "translation (the paper's: the triangle's nodes follow the tool) or point (the contact point "
                        "follows it with least energy); default: the scene's")
      ->check(CLI::IsMember({"translation", "point"}));
  probe_cmd->add_option("--ir-precision", precision, "Storage of M~ and u_B in the IR: f64 or f32 (inversion is always double)")
      ->check(CLI::IsMember({"f64", "f32"}))
      ->capture_default_str();
  probe_cmd->add_option("--patch-rings", probe.patch_rings,
                        "Rings of neighbouring triangles in each IR's contact patch (0-4); default: the scene's")
      ->check(CLI::Range(0, 4));
  probe_cmd->add_flag("--reference", probe.reference,
                      "Full sparse FEM solve instead of the condensed IR (slow; the answer the IR is checked against)");
  probe_cmd->add_flag("--json", probe.json, "Print one JSON object on stdout instead of the table");
  probe_cmd->add_option("--export-vtu", probe.export_vtu, "Write the mesh with the displacement field (.vtu, for ParaView)");
  probe_cmd->add_option("--export-msh", probe.export_msh, "Write the mesh as Gmsh 4.1 ASCII (its node ids are the ones reported)");
  probe_cmd->add_option("--cache-dir", cache_dir, "Directory of the on-disk compliance cache")->capture_default_str();
  probe_cmd->add_flag("--no-disk-cache", no_disk_cache, "Neither read nor write the on-disk compliance cache");

  // replay
  cohaptic::ReplayOptions replay;
  CLI::App* replay_cmd = app.add_subcommand("replay", "Look at a recorded session, re-run it bit for bit, or export it");
  replay_cmd->add_option("file", replay.file, "A recording (.mcap) of a server or a client")->required()->check(CLI::ExistingFile);
  replay_cmd->add_flag("--summary", replay.summary, "What is in it (the default)");
  replay_cmd->add_flag("--verify", replay.verify,
                       "Re-run the recorded inputs through the same computations and compare every force (and IR) bit "
                       "for bit; exit 1 naming the first difference");
  replay_cmd->add_option("--export-csv", replay.export_csv, "Write its records as CSV files in this directory");

  // study
  std::filesystem::path study_file;
  cohaptic::StudyRunOptions study;
  CLI::App* study_cmd = app.add_subcommand(
      "study", "Run a lab study: every trial with real server and client processes, recorded; trials.csv, summary.csv "
               "and figures in --out (re-run to continue an interrupted study)");
  study_cmd->add_option("file", study_file, "The study file (YAML)")->required()->check(CLI::ExistingFile);
  study_cmd->add_option("--out", study.out, "Output directory")->required();
  study_cmd->add_option("--client-program", study.client_program, "cohaptic-client to run (default: the one of this build)");

  // tradeoff
  cohaptic::TradeoffOptions tradeoff;
  CLI::App* tradeoff_cmd = app.add_subcommand(
      "tradeoff", "Measure what each speed/accuracy setting costs and buys on a scene, against the full solve on its "
                  "finest mesh: tradeoff.csv, tradeoff.md and Pareto plots in --out");
  tradeoff_cmd->add_option("--scene", tradeoff.scene, "Scene file (YAML)")->required()->check(CLI::ExistingFile);
  tradeoff_cmd->add_option("--motion", tradeoff.motions, "Trajectory file for each scene tool, in order (repeat)")
      ->required()
      ->check(CLI::ExistingFile);
  tradeoff_cmd->add_option("--out", tradeoff.out, "Output directory")->required();
  tradeoff_cmd->add_option("--divisions", tradeoff.divisions, "Mesh resolutions to measure (box scenes)")
      ->capture_default_str();
  tradeoff_cmd->add_option("--reference-divisions", tradeoff.reference_divisions, "Resolution of the reference mesh (box scenes)")
      ->capture_default_str()
      ->check(CLI::Range(2, 60));
  tradeoff_cmd->add_option("--reference-scene", tradeoff.reference_scene,
                           "Mesh-file scenes: the same scene on a finer mesh, the reference (default: the scene itself)")
      ->check(CLI::ExistingFile);
  tradeoff_cmd->add_option("--sample-rate-hz", tradeoff.sample_rate_hz,
                           "The comparison grid; haptic rates that do not divide it are left out")
      ->capture_default_str()
      ->check(CLI::Range(1000.0, 100000.0));

  // stability
  cohaptic::StabilityOptions stability;
  CLI::App* stability_cmd = app.add_subcommand(
      "stability", "Map where a virtual wall stays stable under the hand model (stiffness x haptic rate x delay), with "
                   "and without the passivity controller: stability.csv, stability.md, stability.svg in --out");
  stability_cmd->add_option("--out", stability.out, "Output directory")->required();
  stability_cmd->add_option("--hand-mass", stability.hand.mass_kg, "Hand model mass [kg]")->capture_default_str();
  stability_cmd->add_option("--hand-stiffness", stability.hand.stiffness_n_per_m, "Hand model stiffness [N/m]")
      ->capture_default_str();
  stability_cmd->add_option("--hand-damping", stability.hand.damping_ns_per_m, "Hand model damping [N s/m]")
      ->capture_default_str();

  // keygen
  std::string key_path;
  CLI::App* keygen_cmd = app.add_subcommand("keygen", "Write a new random session key file (mode 0600)");
  keygen_cmd->add_option("file", key_path, "Where to write it")->required();

  // summarize
  std::filesystem::path summary_server, summary_out;
  std::vector<std::filesystem::path> summary_clients;
  CLI::App* summarize_cmd = app.add_subcommand(
      "summarize", "Merge a session's server and client reports, print a table and judge its health (exit 3 if unhealthy)");
  summarize_cmd->add_option("--server-report", summary_server, "The server's --report")->required()->check(CLI::ExistingFile);
  summarize_cmd->add_option("--client-report", summary_clients, "A client's --report (repeat)")->required()->check(CLI::ExistingFile);
  summarize_cmd->add_option("--out", summary_out, "Write the merged report here");

  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(log_level));
  cohaptic::use_single_blas_thread();

  try {
    if (probe_cmd->parsed()) {
      for (const std::string& text : tool_texts) {
        Eigen::Vector3d point;
        if (const std::string problem = parse_point(text, point); !problem.empty()) {
          fmt::print(stderr, "cohaptic-server probe: --tool: {}\n", problem);
          return 2;
        }
        probe.tools.push_back(point);
      }
      if (!no_disk_cache) probe.cache_directory = cache_dir;
      if (!contact_model.empty())
        probe.contact_model =
            contact_model == "translation" ? cohaptic::ContactModel::node_translation : cohaptic::ContactModel::point_constraint;
      probe.precision = precision == "f32" ? cohaptic::IrPrecision::f32 : cohaptic::IrPrecision::f64;
      return cohaptic::run_probe(probe);
    }
    if (replay_cmd->parsed()) return cohaptic::run_replay(replay);
    if (study_cmd->parsed()) return cohaptic::run_study(study_file, study);
    if (tradeoff_cmd->parsed()) return cohaptic::run_tradeoff(tradeoff);
    if (stability_cmd->parsed()) return cohaptic::run_stability(stability);
    if (summarize_cmd->parsed()) return cohaptic::run_summarize(summary_server, summary_clients, summary_out);
    if (keygen_cmd->parsed()) {
      cohaptic::wire::write_session_key(key_path);
      spdlog::info("wrote a new session key to {}", key_path);
      return 0;
    }
    if (serve.scene.empty()) {
      fmt::print(stderr, "cohaptic-server: --scene is required to serve (or give a subcommand; see --help)\n");
      return 2;
    }
    if (const std::string problem = cohaptic::parse_host_port(listen, serve.host, serve.port, true); !problem.empty()) {
      fmt::print(stderr, "cohaptic-server: --listen: {}\n", problem);
      return 2;
    }
    serve.protocol = protocol == "P0" ? cohaptic::ServeProtocol::p0 : cohaptic::ServeProtocol::p1;
    serve.naive_condensation = condensation == "naive";
    serve.precision = serve_precision == "f32" ? cohaptic::IrPrecision::f32 : cohaptic::IrPrecision::f64;
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
