#include "lab/replay.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <vector>

#include "common/ir/client_condensation.h"
#include "common/ir/warm_start_sphere_contact.h"
#include "common/model/model.h"
#include "common/model/scene_compliance.h"
#include "common/sim/ir_build_options.h"
#include "common/util/host_port.h"
#include "common/scene/load_scene.h"
#include "common/sim/elastic_states.h"
#include "common/sim/scene_simulation.h"
#include "common/haptics/fade_tally.h"
#include "common/haptics/ir_age_histogram.h"
#include "common/util/atomic_file.h"
#include "common/util/csv.h"
#include "common/util/blas_threads.h"
#include "common/util/error.h"
#include "proto/record/recording.h"
#include "proto/wire/ir_convert.h"
#include "proto/wire/vec3_convert.h"
#include "lab/replay_view.h"

namespace cohaptic {
namespace {

using record::Recording;

bool same_bits(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::memcmp(a.data(), b.data(), sizeof(double) * 3) == 0;
}

std::string vec(const Eigen::Vector3d& v) {
  return fmt::format("({:.17g}, {:.17g}, {:.17g})", v.x(), v.y(), v.z());
}

double seconds(std::int64_t ns, std::int64_t start) {
  return static_cast<double>(ns - start) * 1e-9;
}

// What the haptic loop does after evaluating: fade, drop non-finite, limit.
Eigen::Vector3d output_force(const Eigen::Vector3d& evaluated, float fade, double limit) {
  Eigen::Vector3d force = evaluated * static_cast<double>(fade);
  if (!force.allFinite()) force.setZero();
  const double magnitude = force.norm();
  if (magnitude > limit) force *= limit / magnitude;
  return force;
}

VerifyResult verify_client(const Recording& rec) {
  VerifyResult result;
  const std::int64_t start = rec.config.start_time_ns();
  const bool session_p1 = rec.config.protocol() != wire::P0;
  // IRs by epoch, in arrival order (epochs restart when the server does).
  // IRs sent as compliance rows are completed in arrival order, as the client did (it
  // records only those it took, so the held rows follow the same sequence).
  std::multimap<std::uint64_t, std::pair<std::int64_t, std::shared_ptr<const PreparedIR>>> irs;
  ClientCondensation condensation;
  for (const record::RecordedIr& recorded : rec.irs) {
    IntermediateRepresentation ir = wire::from_wire(recorded.ir());
    if (auto* fem = std::get_if<CondensedFemIr>(&ir.body)) condensation.complete(*fem);
    PreparedIR prepared = prepare_ir(std::move(ir));
    if (recorded.has_warm_start()) {  // warmed again, as the client warmed it on arrival
      std::vector<Eigen::Vector3d> remotes;
      for (const wire::Vec3& remote : recorded.warm_start().remotes())
        remotes.push_back(wire::from_wire(remote));
      warm_start_sphere_contact(prepared, wire::from_wire(recorded.warm_start().own()), remotes);
    }
    irs.emplace(recorded.ir().epoch(),
                std::make_pair(recorded.time_ns(),
                               std::make_shared<const PreparedIR>(std::move(prepared))));
  }
  std::vector<std::tuple<std::int64_t, std::uint64_t, Eigen::Vector3d>>
      forces;  // P0: arrival, epoch, force
  for (const record::ReceivedDatagram& d : rec.datagrams)
    if (d.datagram().has_force())
      forces.emplace_back(d.receive_time_ns(), d.datagram().force().ir_epoch(),
                          wire::from_wire(d.datagram().force().force()));

  // Each IR's evaluation state, made when a tick first uses the IR and advanced by every
  // tick that uses it, as the haptic loop did (a dynamic body's force depends on it).
  std::map<const PreparedIR*, EvaluationState> states;
  EvaluationCarry carry;  // what each IR's evaluator hands on to the next
  Eigen::Vector3d last_resolved =
      Eigen::Vector3d::Zero();  // held over unresolved sphere solves, as the loop does
  const auto fail = [&](std::size_t i, const record::HapticTick& tick, const std::string& what) {
    result.ok = false;
    result.first_difference = fmt::format("haptic tick {} (t = {:.6f} s, IR epoch {}): {}", i,
                                          seconds(tick.time_ns(), start), tick.ir_epoch(), what);
  };
  for (std::size_t i = 0; i < rec.ticks.size() && result.ok; ++i) {
    const record::HapticTick& tick = rec.ticks[i];
    const Eigen::Vector3d evaluated = wire::from_wire(tick.evaluated());
    Eigen::Vector3d expected = Eigen::Vector3d::Zero();
    // The protocol the tick used: the session's, unless the server switched it.
    const bool p1 =
        tick.protocol() == wire::PROTOCOL_UNSPECIFIED ? session_p1 : tick.protocol() == wire::P1;
    if (tick.own_valid() && tick.ir_epoch() != 0) {
      if (p1) {
        // The newest IR of that epoch received by then.
        std::shared_ptr<const PreparedIR> ir;
        const auto [first, last] = irs.equal_range(tick.ir_epoch());
        for (auto it = first; it != last; ++it)
          if (it->second.first <= tick.time_ns() || !ir) ir = it->second.second;
        if (!ir) {
          fail(i, tick, "the IR it used was not recorded");
          break;
        }
        std::vector<Eigen::Vector3d> remotes;
        for (const wire::Vec3& r : tick.remotes()) remotes.push_back(wire::from_wire(r));
        auto state = states.find(ir.get());
        if (state == states.end())
          state = states.emplace(ir.get(), make_evaluation_state(*ir)).first;
        const ForceSample sample =
            evaluate_force_in_turn(*ir, state->second, carry, wire::from_wire(tick.own()), remotes,
                                   tick.dt(), tick.buttons());
        expected = (sample.flags & kContactUnresolved) ? last_resolved : sample.force;
        last_resolved = expected;
      } else {
        // P0: the force held is one the server sent under that epoch and had arrived.
        expected = Eigen::Vector3d::Constant(std::nan(""));
        for (const auto& [arrival, epoch, force] : forces)
          if (epoch == tick.ir_epoch() && arrival <= tick.time_ns() && same_bits(force, evaluated))
            expected = force;
      }
    }
    if (!same_bits(expected, evaluated)) {
      fail(i, tick,
           fmt::format("recorded evaluated force {}, replayed {}", vec(evaluated), vec(expected)));
      break;
    }
    const Eigen::Vector3d force = output_force(evaluated, tick.fade(), rec.config.force_limit());
    if (!same_bits(force, wire::from_wire(tick.force()))) {
      fail(i, tick,
           fmt::format("recorded output force {}, replayed {}", vec(wire::from_wire(tick.force())),
                       vec(force)));
      break;
    }
    result.checked += 2;
  }
  return result;
}

VerifyResult verify_server(const Recording& rec, const SceneFileAccess& scene_files) {
  use_single_blas_thread();  // as the server ran: the same rounding in every solve
  VerifyResult result;
  const record::SessionConfig& config = rec.config;
  const std::int64_t start = config.start_time_ns();
  const Scene scene = parse_scene(config.scene_yaml(), config.scene_file(), scene_files);
  const Model model = build_model(scene);
  // As the server loaded it: the whole surface when any condition it served held nodes.
  bool holds_nodes = config.injected().step_nodes() > 0;
  for (const record::SimulationStep& step : rec.steps)
    holds_nodes = holds_nodes || step.condition_switch().injected().step_nodes() > 0;
  const bool whole_surface =
      holds_nodes || !model.obstacles.empty() || !model.scene.interactions.empty();
  const SceneCompliance compliance = prepare_scene_compliance(model, whole_surface, std::nullopt);
  SimulationOptions options;
  options.ir = ir_build_options(scene.haptic);
  options.ir.precision = config.ir_f32() ? IrPrecision::f32 : IrPrecision::f64;
  options.step_delay_nodes = static_cast<int>(config.injected().step_nodes());
  options.naive_every_step = config.injected().condensation() == "naive";
  SceneSimulation simulation(model, compliance.per_body, scene.tools, options);

  std::size_t next_ir = 0;
  std::string expected_bytes, replayed_bytes;
  for (std::size_t i = 0; i < rec.steps.size() && result.ok; ++i) {
    const record::SimulationStep& step = rec.steps[i];
    const auto fail = [&](const std::string& what) {
      result.ok = false;
      result.first_difference = fmt::format("simulation step {} (t = {:.6f} s): {}", i,
                                            seconds(step.time_ns(), start), what);
    };
    if (step.has_condition_switch())
      simulation.set_step_delay_nodes(
          static_cast<int>(step.condition_switch().injected().step_nodes()));
    for (const record::ToolInput& tool : step.tools()) {
      if (tool.known())
        simulation.set_tool(static_cast<int>(tool.slot()), wire::from_wire(tool.position()),
                            tool.buttons());
      else
        simulation.clear_tool(static_cast<int>(tool.slot()));
    }
    const StepReport report = simulation.step(step.simulation_time());
    if (report.rebuilt != step.rebuilt()) {
      fail(fmt::format("recorded {} the IRs, the replay {}", step.rebuilt() ? "rebuilt" : "kept",
                       report.rebuilt ? "rebuilt them" : "kept them"));
      break;
    }
    if (report.fractured_m2 != step.fractured_m2() || report.vaporised_m2 != step.vaporised_m2()) {
      fail(fmt::format(
          "recorded {:.9g} mm^2 fractured and {:.9g} mm^2 vaporised, the replay {:.9g} and {:.9g}",
          1e6 * step.fractured_m2(), 1e6 * step.vaporised_m2(), 1e6 * report.fractured_m2,
          1e6 * report.vaporised_m2));
      break;
    }
    std::vector<std::uint32_t> pressing;
    for (int user = 0; user < simulation.user_count(); ++user)
      if (simulation.pressing(user)) pressing.push_back(static_cast<std::uint32_t>(user));
    if (!std::equal(pressing.begin(), pressing.end(), step.pressing_slots().begin(),
                    step.pressing_slots().end())) {
      fail(fmt::format("recorded {} users pressing, the replay {}", step.pressing_slots_size(),
                       pressing.size()));
      break;
    }
    if (report.rebuilt) {
      for (int user = 0; user < simulation.user_count() && result.ok; ++user) {
        const auto prepared = simulation.ir(user);
        if (!prepared || !simulation.ir_changed(user)) continue;
        while (next_ir < rec.irs.size() && rec.irs[next_ir].repeat())
          ++next_ir;  // sent again, built before
        if (next_ir >= rec.irs.size()) {
          fail(fmt::format("the replay built an IR for user {} that was not recorded", user));
          break;
        }
        rec.irs[next_ir].ir().SerializeToString(&expected_bytes);
        wire::to_wire(prepared->ir).SerializeToString(&replayed_bytes);
        if (expected_bytes != replayed_bytes)
          fail(fmt::format("the IR for user {} (epoch {}) differs from the recorded one", user,
                           prepared->ir.epoch));
        ++next_ir;
        ++result.checked;
      }
    }
    for (const record::ServerForce& recorded : step.forces()) {
      const Eigen::Vector3d force = simulation.force(static_cast<int>(recorded.slot())).force;
      if (!same_bits(force, wire::from_wire(recorded.force()))) {
        fail(fmt::format("P0 force for user {}: recorded {}, replayed {}", recorded.slot(),
                         vec(wire::from_wire(recorded.force())), vec(force)));
        break;
      }
      ++result.checked;
    }
    // Same side effects as live: a display or view frame solves every linear elastic body's state.
    if (step.display_frame()) solve_elastic_states(simulation);
  }
  return result;
}

void print_summary(const Recording& rec) {
  const record::SessionConfig& c = rec.config;
  const auto span = [&](auto first, auto last) { return seconds(last, first); };
  std::int64_t first = std::numeric_limits<std::int64_t>::max(), last = 0;
  const auto see = [&](std::int64_t t) {
    first = std::min(first, t);
    last = std::max(last, t);
  };
  for (const auto& t : rec.ticks) see(t.time_ns());
  for (const auto& s : rec.steps) see(s.time_ns());
  for (const auto& d : rec.datagrams) see(d.receive_time_ns());
  fmt::print("recording   {}{}\n", rec.file.string(),
             rec.truncated ? fmt::format(" (TRUNCATED: {})", rec.truncation) : "");
  if (rec.truncated) fmt::print("integrity   {}\n", record::describe_cut(rec));
  fmt::print("role        {}{}\n", c.role(),
             c.role() == "client"
                 ? fmt::format(", user '{}' in slot {}, device {}", c.user(), c.slot(), c.device())
                 : "");
  fmt::print("scene       {} ({})\n", c.scene_name(),
             c.scene_file().empty() ? "as served" : c.scene_file());
  fmt::print("protocol    {}; session {:016x}\n", c.protocol() == wire::P0 ? "P0" : "P1",
             c.session());
  const record::InjectedDelays& d = c.injected();
  if (c.role() == "server")
    fmt::print(
        "injected    shift {:g} ms + U(0, {:g}) ms, loss {:g}, reorder {:g}, seed {}; step nodes "
        "{}, sim rate {:g} Hz, "
        "{} condensation\n",
        d.shift_delay_ms(), d.jitter_ms(), d.loss(), d.reorder(), d.seed(), d.step_nodes(),
        d.sim_rate_hz(), d.condensation());
  fmt::print("duration    {:.3f} s\n", first <= last ? span(first, last) : 0.0);
  fmt::print("records     {} haptic ticks, {} simulation steps, {} IRs, {} datagrams, {} events\n",
             rec.ticks.size(), rec.steps.size(), rec.irs.size(), rec.datagrams.size(),
             rec.events.size());
  if (!rec.steps.empty() &&
      (rec.steps.back().fractured_m2() > 0 || rec.steps.back().vaporised_m2() > 0))
    fmt::print("separated   {:.2f} mm^2 by the last step: {:.2f} fractured, {:.2f} vaporised\n",
               1e6 * (rec.steps.back().fractured_m2() + rec.steps.back().vaporised_m2()),
               1e6 * rec.steps.back().fractured_m2(), 1e6 * rec.steps.back().vaporised_m2());
  if (c.role() == "server")
    fmt::print("view        {} frames, {} client status reports{}\n", rec.view_frames.size(),
               rec.client_statuses.size(),
               rec.view_frames.empty()
                   ? " (recorded without --view: replay --view has no frames to show)"
                   : "");
  if (!rec.ticks.empty()) {
    // The client report's counters, from the ticks: each tick counts as the median period.
    std::vector<std::int64_t> periods;
    for (std::size_t k = 1; k < rec.ticks.size(); ++k)
      periods.push_back(rec.ticks[k].time_ns() - rec.ticks[k - 1].time_ns());
    std::nth_element(periods.begin(),
                     periods.begin() + static_cast<std::ptrdiff_t>(periods.size() / 2),
                     periods.end());
    const double period_s =
        periods.empty() ? 0.0 : static_cast<double>(periods[periods.size() / 2]) * 1e-9;
    double peak = 0;
    std::size_t at_limit = 0;
    FadeTally fades;
    Histogram ir_ages = ir_age_histogram();
    for (const auto& t : rec.ticks) {
      if (t.has_ir_age_ns()) ir_ages.record(t.ir_age_ns());
      const double force = wire::from_wire(t.force()).norm();
      peak = std::max(peak, force);
      if (c.force_limit() > 0 && force >= c.force_limit() * (1 - 1e-9)) ++at_limit;
      fades.tick(t.fade(), wire::from_wire(t.evaluated()).squaredNorm() > 0, period_s);
    }
    fmt::print("force       peak {:.4f} N; {} ticks at the force limit ({:g} N)\n", peak, at_limit,
               c.force_limit());
    fmt::print("fades       {} while pushing ({:.0f} ms in all, the longest {:.0f} ms)\n",
               fades.count, fades.total_s * 1e3, fades.longest_s * 1e3);
    const auto ms = [](std::int64_t ns) { return static_cast<double>(ns) * 1e-6; };
    if (ir_ages.count() > 0)
      fmt::print("IR age      p50 {:.1f} ms, p99 {:.1f} ms, max {:.1f} ms\n",
                 ms(ir_ages.quantile(0.5)), ms(ir_ages.quantile(0.99)), ms(ir_ages.max()));
    else
      fmt::print(
          "IR age      not recorded (no tick had an IR yet, or the recording predates IR ages)\n");
  }
  for (const auto& e : rec.events)
    fmt::print("event       {:9.3f} s  {}: {}\n", seconds(e.time_ns(), c.start_time_ns()), e.kind(),
               e.text());
}

void export_csv(const Recording& rec, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const std::int64_t start = rec.config.start_time_ns();
  if (!rec.ticks.empty()) {
    AtomicFile out(dir / "haptic.csv");
    out.write(
        "time_s,own_x,own_y,own_z,own_valid,force_x,force_y,force_z,evaluated_x,evaluated_y,"
        "evaluated_z,ir_epoch,flags,fade,ir_age_ms");
    out.write(",remote_x,remote_y,remote_z,protocol,buttons\n");
    for (const auto& t : rec.ticks) {
      const Eigen::Vector3d o = wire::from_wire(t.own()), f = wire::from_wire(t.force()),
                            e = wire::from_wire(t.evaluated());
      const Eigen::Vector3d r = t.remotes_size() ? wire::from_wire(t.remotes(0))
                                                 : Eigen::Vector3d::Constant(std::nan(""));
      out.print(
          "{:.9f},{:.17g},{:.17g},{:.17g},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{},{},"
          "{},{},{:.17g},{:.17g},{:.17g},{},{}\n",
          seconds(t.time_ns(), start), o.x(), o.y(), o.z(), t.own_valid() ? 1 : 0, f.x(), f.y(),
          f.z(), e.x(), e.y(), e.z(), t.ir_epoch(), t.flags(), t.fade(),
          t.has_ir_age_ns() ? fmt::format("{:.4f}", static_cast<double>(t.ir_age_ns()) * 1e-6)
                            : std::string(),
          r.x(), r.y(), r.z(),
          t.protocol() == wire::P0   ? "P0"
          : t.protocol() == wire::P1 ? "P1"
                                     : "",
          t.buttons());
    }
    out.commit();
  }
  if (!rec.steps.empty()) {
    AtomicFile out(dir / "steps.csv");
    out.write(
        "time_s,simulation_time_s,slot,known,x,y,z,buttons,rebuilt,boundary_nodes,condition_"
        "switch,fractured_mm2,vaporised_mm2\n");
    for (const auto& s : rec.steps)
      for (const auto& tool : s.tools()) {
        const Eigen::Vector3d p = wire::from_wire(tool.position());
        out.print("{:.9f},{:.9f},{},{},{:.17g},{:.17g},{:.17g},{},{},{},{},{:.9g},{:.9g}\n",
                  seconds(s.time_ns(), start), s.simulation_time(), tool.slot(),
                  tool.known() ? 1 : 0, p.x(), p.y(), p.z(), tool.buttons(), s.rebuilt() ? 1 : 0,
                  s.boundary_nodes(), csv_field(s.condition_switch().name()),
                  1e6 * s.fractured_m2(), 1e6 * s.vaporised_m2());
      }
    out.commit();
  }
  {
    AtomicFile out(dir / "tool_samples.csv");
    out.write(
        "receive_time_s,sender,sequence,sender_time_ns,user,sample_time_ns,x,y,z,valid,buttons\n");
    for (const auto& d : rec.datagrams) {
      if (!d.datagram().has_tool()) continue;
      const wire::ToolSample& t = d.datagram().tool();
      const Eigen::Vector3d p = wire::from_wire(t.position());
      out.print("{:.9f},{},{},{},{},{},{:.17g},{:.17g},{:.17g},{},{}\n",
                seconds(d.receive_time_ns(), start), d.datagram().header().sender(),
                d.datagram().header().sequence(), d.datagram().header().sender_time_ns(), t.user(),
                t.sample_time_ns(), p.x(), p.y(), p.z(), t.valid() ? 1 : 0, t.buttons());
    }
    out.commit();
  }
  {
    AtomicFile out(dir / "irs.csv");
    out.write("time_s,user,epoch,simulation_time_s,contact_nodes,boundary_dofs,bytes\n");
    for (const auto& r : rec.irs)
      out.print("{:.9f},{},{},{:.9f},{},{},{}\n", seconds(r.time_ns(), start), r.ir().user(),
                r.ir().epoch(), r.ir().simulation_time(), r.ir().fem().row_node_count(),
                r.ir().fem().boundary_displacement_f64_size() +
                    r.ir().fem().boundary_displacement_f32_size(),
                r.ir().ByteSizeLong());
    out.commit();
  }
  {
    AtomicFile out(dir / "events.csv");
    out.write("time_s,kind,text\n");
    for (const auto& e : rec.events) {
      std::string text = e.text();
      std::replace(text.begin(), text.end(), '"', '\'');
      out.print("{:.9f},{},\"{}\"\n", seconds(e.time_ns(), start), e.kind(), text);
    }
    out.commit();
  }
  spdlog::info("exported CSV files to {}", dir.string());
}

}  // namespace

VerifyResult verify_recording(const std::filesystem::path& file) {
  return verify_recording(
      file, {.confined_to = std::filesystem::absolute(file).parent_path(), .gmsh_scripts = false});
}

VerifyResult verify_recording(const std::filesystem::path& file,
                              const SceneFileAccess& scene_files) {
  const Recording rec = record::read_recording(file);
  if (!rec.has_config)
    throw Error(fmt::format("{}: the recording has no configuration: it cannot be verified",
                            file.string()));
  // Re-running needs this build's IR format; a recording of another is refused, never misread.
  for (const record::RecordedIr& recorded : rec.irs)
    if (recorded.ir().format_version() < IntermediateRepresentation::kOldestReadableVersion ||
        recorded.ir().format_version() > IntermediateRepresentation::kFormatVersion)
      throw Error(fmt::format(
          "{}: its IRs are in format version {}, and this build re-runs format version {} (and "
          "{}): "
          "verify it with the cohaptic build that recorded it (format 1: builds before scenes had "
          "several bodies; 2: before compliance rows)",
          file.string(), recorded.ir().format_version(), IntermediateRepresentation::kFormatVersion,
          IntermediateRepresentation::kOldestReadableVersion));
  return rec.config.role() == "server" ? verify_server(rec, scene_files) : verify_client(rec);
}

int run_replay(const ReplayOptions& options) {
  const Recording rec = record::read_recording(options.file);
  const bool summary = options.summary || (!options.verify && options.export_csv.empty());
  if (summary) print_summary(rec);
  if (!options.export_csv.empty()) export_csv(rec, options.export_csv);
  if (!options.view.empty()) {
    ReplayViewOptions view;
    if (const std::string problem = parse_host_port(options.view, view.host, view.port, true);
        !problem.empty())
      throw Error("--view: " + problem);
    view.token_file = options.view_token_file;
    return serve_replay(rec, view);
  }
  if (options.verify) {
    if (rec.truncated) fmt::print("verify: {}\n", record::describe_cut(rec));
    const VerifyResult result =
        options.scene_dir ? verify_recording(options.file, {.confined_to = *options.scene_dir,
                                                            .gmsh_scripts = true})
                          : verify_recording(options.file);
    if (!result.ok) {
      fmt::print("verify: DIFFERENT after {} identical values: {}\n", result.checked,
                 result.first_difference);
      return 1;
    }
    fmt::print("verify: identical: {} {} re-run and compared bit for bit{}\n", result.checked,
               rec.config.role() == "server" ? "IRs and forces" : "forces",
               rec.truncated ? " (recording truncated)" : "");
  }
  return 0;
}

LabCommand add_replay_command(CLI::App& lab) {
  auto options = std::make_shared<ReplayOptions>();
  CLI::App* command = lab.add_subcommand(
      "replay", "Look at a recorded session, re-run it bit for bit, or export it");
  command->add_option("file", options->file, "A recording (.mcap) of a server or a client")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_flag("--summary", options->summary, "What is in it (the default)");
  command->add_flag("--verify", options->verify,
                    "Re-run the recorded inputs through the same computations and compare every "
                    "force (and IR) bit "
                    "for bit; exit 1 naming the first difference");
  command
      ->add_option(
          "--scene-dir", options->scene_dir,
          "With --verify of a server recording: the folder its scene's files (meshes, surfaces, "
          "gmsh "
          "scripts) may be read from (default: the recording's own folder, and no gmsh script: a "
          "recording may come from anyone)")
      ->check(CLI::ExistingDirectory);
  command->add_option("--export-csv", options->export_csv,
                      "Write its records as CSV files in this directory");
  command->add_option(
      "--view", options->view,
      "Serve a server recording made with --view in the live view's page at HOST:PORT, with a "
      "timeline (play, pause, speed, scrub, jump to the largest force), until SIGINT");
  command
      ->add_option(
          "--view-token-file", options->view_token_file,
          "The page's access token (required off loopback; without it a random one is printed)")
      ->check(CLI::ExistingFile);
  return {command, [options] { return run_replay(*options); }};
}

}  // namespace cohaptic
