// cohaptic-lab: the offline tools, one subcommand each (docs/lab-tools.md):
//   probe      static forces at tool positions          tradeoff   speed against accuracy
//   replay     look at, re-run or export a recording    stability  the stability map of a wall
//   study      a lab study, trial by trial              summarize  merge reports, judge a session
//   keygen     a new session key file, or a participant key file
//   hertz      a sphere in a block, against Hertz
//   objects-push  the several-objects pushing test: back free, fixed, on an elastic box
//   ir-bytes   a client's IR bytes, and what f32, M~ deltas or compliance rows would send
//   separation-pull  the separation-forces paper's Fig. 10 on a scene's separating interface
// Each tool adds its own subcommand (lab/lab_command.h). A tool that needs the server or the
// client (study) starts them as processes; cohaptic-lab links neither.
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <vector>

#include "common/util/blas_threads.h"
#include "common/util/error.h"
#include "common/util/log_to_stderr.h"
#include "lab/hertz.h"
#include "lab/ir_bytes.h"
#include "lab/keygen.h"
#include "lab/objects_push.h"
#include "lab/probe.h"
#include "lab/replay.h"
#include "lab/separation_pull.h"
#include "lab/session_summary.h"
#include "lab/stability.h"
#include "lab/study.h"
#include "lab/tradeoff.h"

int main(int argc, char** argv) {
  cohaptic::log_to_stderr();

  CLI::App app{
      "cohaptic-lab: the offline tools of cohaptic (probing, replay, studies, measurements)."};
  app.require_subcommand(1);
  app.fallthrough();  // --log-level may follow the subcommand
  std::string log_level = "info";
  app.add_option("--log-level", log_level,
                 "Log verbosity on stderr: trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();
  const std::vector<cohaptic::LabCommand> commands = {
      cohaptic::add_probe_command(app),          cohaptic::add_replay_command(app),
      cohaptic::add_study_command(app),          cohaptic::add_tradeoff_command(app),
      cohaptic::add_stability_command(app),      cohaptic::add_summarize_command(app),
      cohaptic::add_keygen_command(app),         cohaptic::add_hertz_command(app),
      cohaptic::add_objects_push_command(app),   cohaptic::add_ir_bytes_command(app),
      cohaptic::add_separation_pull_command(app)};

  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(log_level));
  cohaptic::use_single_blas_thread();
  try {
    for (const cohaptic::LabCommand& command : commands)
      if (command.subcommand->parsed()) return command.run();
    return 2;  // unreachable: CLI11 requires one subcommand
  } catch (const cohaptic::Error& e) {
    spdlog::error("{}", e.what());
    return 1;
  } catch (const std::exception& e) {
    spdlog::error("unexpected failure: {}", e.what());
    return 1;
  }
}
