// cohaptic-client: a haptic client. Joins a cohaptic-server session, runs the haptic loop
// against a device at its rate, and writes a report at the end. See docs/client.md.
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <fstream>
#include <optional>
#include <thread>

#include "client/client_network.h"
#include "client/device/make_device.h"
#include "client/device/trajectory_reach.h"
#include "client/haptic_loop.h"
#include "client/timer_floors.h"
#include "common/util/host_port.h"
#include "common/util/atomic_file.h"
#include "common/util/blas_threads.h"
#include "common/util/error.h"
#include "common/util/keep_freed_memory.h"
#include "common/util/log_to_stderr.h"
#include "proto/wire/user_name.h"

int main(int argc, char** argv) {
  cohaptic::log_to_stderr();
  cohaptic::keep_freed_memory();

  CLI::App app{"cohaptic-client: a haptic client of a cohaptic-server session"};
  std::string server = "127.0.0.1:7400", device_spec, log_level = "info", playout = "fixed";
  cohaptic::ClientOptions options;
  cohaptic::HapticLoopSettings settings;
  std::filesystem::path report_path;
  double rate_hz = 0, join_timeout_s = 10;
  bool best_effort = false;
  int slot = -1;
  app.add_option("--server", server, "HOST:PORT of the server")->capture_default_str();
  app.add_option("--user", options.user_name, "Your name, shown to the other users")->required();
  std::string device_forms;
  for (const std::string& form : cohaptic::device_spec_forms())
    device_forms += (device_forms.empty() ? "" : "; ") + form;
  app.add_option("--device", device_spec, "The device: " + device_forms)->required();
  app.add_option("--key-file", options.key_file,
                 "Key file (mode 0600): your participant key (cohaptic-lab keygen --participant), "
                 "or the session key")
      ->check(CLI::ExistingFile);
  app.add_option(
      "--slot", slot,
      "Ask for this user slot (tool) instead of the first free one (a participant key: its own)");
  bool no_encryption = false;
  app.add_flag("--no-encryption", no_encryption,
               "Send frames and datagrams in clear (still authenticated), and accept the server's "
               "in clear; the server "
               "must be run with --no-encryption too");
  app.add_option("--rate-hz", rate_hz, "Haptic loop rate (default: the scene's, usually 1000)")
      ->check(CLI::Range(0.0, 10000.0));
  app.add_option("--duration", settings.duration_s,
                 "Stop after S seconds (0: when the device's script ends, or SIGINT)")
      ->capture_default_str();
  app.add_option("--playout", playout, "Remote tool playout: newest, fixed or adaptive")
      ->check(CLI::IsMember({"newest", "fixed", "adaptive"}))
      ->capture_default_str();
  app.add_option("--playout-delay-ms", settings.playout_delay_s,
                 "Fixed playout delay [ms] (also the adaptive start)")
      ->transform([](const std::string& ms) { return std::to_string(std::stod(ms) * 1e-3); });
  app.add_option("--fade-ms", settings.fade_s,
                 "Time to fade the force out once the IR is too old [ms]")
      ->transform([](const std::string& ms) { return std::to_string(std::stod(ms) * 1e-3); });
  app.add_flag("--best-effort", best_effort, "Do not try SCHED_FIFO and mlockall");
  app.add_flag("--passivity-control", settings.passivity_control,
               "Filter the force through a passivity observer/controller (stable against stiff, "
               "delayed or stepwise "
               "forces, at some cost in transparency; docs/stability.md \"Stability\")");
  app.add_option(
         "--passivity-mass", settings.passivity_mass_kg,
         "The lightest mass expected at the tool [kg]: caps the controller's damping at m / (2 T)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--report", report_path, "Write a JSON report here at exit");
  std::filesystem::path record_path;
  app.add_option(
      "--record", record_path,
      "Record the session here (MCAP: configuration, datagrams, IRs, every haptic tick, events)");
  app.add_option("--join-timeout", join_timeout_s,
                 "Give up if the server does not welcome us within S seconds")
      ->capture_default_str();
  app.add_option("--log-level", log_level, "Log verbosity: trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(log_level));
  // The I/O thread condenses compliance rows through BLAS: on one thread it neither competes
  // with the haptic loop for the cores nor rounds differently from `replay --verify`.
  cohaptic::use_single_blas_thread();

  try {
    if (const std::string problem =
            cohaptic::parse_host_port(server, options.host, options.port, false);
        !problem.empty()) {
      fmt::print(stderr, "cohaptic-client: --server: {}\n", problem);
      return 2;
    }
    if (const std::string problem = cohaptic::wire::user_name_problem(options.user_name);
        !problem.empty()) {
      fmt::print(stderr, "cohaptic-client: --user: {}\n", problem);
      return 2;
    }
    options.requested_slot = slot;
    options.haptic_rate_hz = rate_hz;
    options.encrypt = !no_encryption;
    auto channels = std::make_unique<cohaptic::HapticChannels>();
    // The device's spec and file are checked before we join: a typo takes no seat.
    const std::optional<cohaptic::Trajectory> path = cohaptic::device_path(device_spec);
    cohaptic::ClientNetwork network(options, *channels);
    const cohaptic::WelcomeInfo welcome = network.start(join_timeout_s);
    if (path)
      if (const std::string far = cohaptic::trajectory_reach_warning(*path, welcome.surface_bounds);
          !far.empty())
        spdlog::warn("{}", far);

    std::unique_ptr<cohaptic::HapticDevice> device =
        cohaptic::make_device(device_spec, welcome.force_limit);
    device->start();
    settings.rate_hz = rate_hz > 0 ? rate_hz : welcome.haptic_rate_hz;
    settings.protocol = welcome.protocol;
    settings.force_limit = std::min(welcome.force_limit, device->force_limit());
    settings.max_age_s = welcome.ir_max_age_s;
    settings.playout = cohaptic::parse_playout_policy(playout);
    settings.realtime = !best_effort;
    spdlog::info(
        "haptic loop at {:g} Hz with {}; the force sent to it is limited to {:g} N (the smaller of "
        "the "
        "device's and the scene's)",
        settings.rate_hz, device->describe(), settings.force_limit);

    if (!record_path.empty())
      network.record_session(record_path, device->describe(), settings.force_limit);
    cohaptic::HapticLoop loop(*device, *channels, settings);
    cohaptic::TimerFloors floors;  // one bare timer on each CPU the haptic thread may run on
    network.report_status(loop.metrics(), floors);
    // Before any real-time thread: one that locked the memory would stall a floor meanwhile.
    if (settings.realtime) cohaptic::lock_process_memory();
    floors.start(settings.rate_hz, settings.realtime);
    std::thread haptic_thread([&] { loop.run(network.stop_requested()); });
    haptic_thread.join();
    floors.stop();
    device->stop();
    network.stop();

    const cohaptic::HapticMetrics& m = loop.metrics();
    nlohmann::json report;
    report["user"] = options.user_name;
    report["slot"] = welcome.slot;
    report["device"] = device->describe();
    report["protocol"] =
        welcome.protocol == cohaptic::HapticProtocol::p1 ? "P1" : "P0";  // at the join
    report["protocol_switches"] = m.protocol_switches;  // the server switched conditions
    report["rate_setting_hz"] = settings.rate_hz;
    report["haptic_rate_hz"] = m.elapsed_s > 0 ? static_cast<double>(m.ticks) / m.elapsed_s : 0.0;
    report["ticks"] = m.ticks;
    report["period_us"] = cohaptic::quantiles_us(m.period_ns);
    report["missed_deadlines"] = m.missed_deadlines;
    report["timer_floor"] = floors.report();
    report["realtime"] = m.realtime;
    // Of the IR in use (P1) or the force (P0), every tick that had one; it fades past fade_after.
    report["ir_age_ms"] = {{"p50", static_cast<double>(m.ir_age_ns.quantile(0.5)) * 1e-6},
                           {"p99", static_cast<double>(m.ir_age_ns.quantile(0.99)) * 1e-6},
                           {"max", static_cast<double>(m.ir_age_ns.max()) * 1e-6},
                           {"fade_after", settings.max_age_s * 1e3}};
    report["force_n"] = {{"peak", m.peak_force}, {"clamped_ticks", m.clamped}};
    report["coupling_n"] = {{"peak", m.peak_coupling}, {"measured", m.coupling_measured}};
    report["force_step_on_ir_switch_n"] = m.largest_step_on_ir_switch;
    report["fades"] = {
        {"count", m.fades.count}, {"total_s", m.fades.total_s}, {"longest_s", m.fades.longest_s}};
    if (settings.passivity_control)
      report["passivity_controller"] = {{"active_ticks", loop.passivity().active_ticks()},
                                        {"dissipated_j", loop.passivity().dissipated_energy()}};
    report["non_finite_ticks"] = m.non_finite;
    report["contact_unresolved_ticks"] = m.contact_unresolved;
    report["elapsed_s"] = m.elapsed_s;
    report.update(network.report());
    spdlog::info(
        "done: {} ticks at {:.1f} Hz, period p99 {:.0f} us (timer floor p99 {:.0f} us), peak force "
        "{:.3f} N, "
        "coupling {:.3f} N",
        m.ticks, report["haptic_rate_hz"].get<double>(), report["period_us"]["p99"].get<double>(),
        report["timer_floor"]["period_us"]["p99"].get<double>(), m.peak_force, m.peak_coupling);
    if (m.fades.count > 0)
      spdlog::warn(
          "the force faded {} time(s) while pushing ({:.0f} ms in all, the longest {:.0f} ms): its "
          "{} came too late",
          m.fades.count, m.fades.total_s * 1e3, m.fades.longest_s * 1e3,
          settings.protocol == cohaptic::HapticProtocol::p1 ? "IR" : "force");
    if (!report_path.empty()) {
      if (report_path.has_parent_path())
        std::filesystem::create_directories(report_path.parent_path());
      cohaptic::AtomicFile out(report_path);
      out.write(report.dump(2));
      out.commit();
    }
    return 0;
  } catch (const cohaptic::Error& e) {
    spdlog::error("{}", e.what());
    return 1;
  } catch (const std::exception& e) {
    spdlog::error("unexpected failure: {}", e.what());
    return 1;
  }
}
