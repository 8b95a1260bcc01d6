#include "lab/tradeoff_mass_spring.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "common/ir/evaluate_force.h"
#include "common/model/model.h"
#include "common/sim/mass_spring_simulation.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"
#include "common/util/percentile.h"
#include "common/util/stopwatch.h"
#include "lab/tradeoff.h"

namespace cohaptic {
namespace {

MassSpringObjectSpec& only_mass_spring_object(Scene& scene) {
  MassSpringObjectSpec* object =
      scene.objects.size() == 1 ? std::get_if<MassSpringObjectSpec>(&scene.objects.front().body)
                                : nullptr;
  if (!object)
    throw Error(
        fmt::format("{}: the mass-spring trade-off needs a scene whose only object is mass_spring",
                    scene.file.string()));
  return *object;
}

std::string sections_name(const MassSpringTradeoffRow& row) {
  return row.whole ? std::string("whole") : std::to_string(row.setting.sections);
}

}  // namespace

std::vector<MassSpringTradeoffSetting> mass_spring_tradeoff_grid(const Scene& scene) {
  Scene copy = scene;
  only_mass_spring_object(copy);
  std::vector<MassSpringTradeoffSetting> grid;
  for (const int sections : {1, 2, 4, 8, std::numeric_limits<int>::max()})
    for (const double rate : {10.0, 30.0, 100.0, 300.0, 1000.0})
      if (rate <= scene.haptic.rate_hz) grid.push_back({sections, rate});
  return grid;
}

MassSpringTradeoffRow run_mass_spring_setting(const Scene& scene,
                                              const MassSpringTradeoffSetting& setting,
                                              const std::vector<Trajectory>& motions) {
  Scene varied = scene;
  MassSpringObjectSpec& object = only_mass_spring_object(varied);
  if (motions.size() != varied.tools.size())
    throw Error(
        fmt::format("tradeoff: {} motions for the scene's {} tools (give one --motion per tool)",
                    motions.size(), varied.tools.size()));
  object.ir.rate_hz = setting.ir_rate_hz;
  const Model model = build_model(varied);
  const MassSpringModel& built = std::get<MassSpringModel>(model.bodies.front());
  MassSpringModel body = built;
  body.spec.ir.sections = std::min(setting.sections, body.section_count);
  MassSpringTradeoffRow row;
  row.setting = setting;
  row.whole = 2 * body.spec.ir.sections + 1 >= body.section_count;

  // No force limit: the physics is compared, not the limiter.
  MassSpringSimulation server(body, 0, varied.tools, std::numeric_limits<double>::infinity(),
                              1 / varied.haptic.rate_hz);
  const std::size_t users = varied.tools.size();
  std::vector<std::shared_ptr<const PreparedIR>> client_ir(users);
  std::vector<EvaluationState> client_state(users);
  std::vector<Eigen::Vector3d> positions(users);
  std::array<Eigen::Vector3d, kMaxNetworkTools> remotes;
  std::vector<double> evaluation_us;
  double duration = 0;
  for (const Trajectory& motion : motions) duration = std::max(duration, motion.duration());
  const double dt = 1 / varied.haptic.rate_hz;
  const auto ticks = static_cast<long>(std::floor(duration / dt)) + 1;
  double sum_squared = 0, worst = 0, worst_agreeing = 0, ir_nodes = 0, bytes = 0;
  for (long k = 0; k < ticks; ++k) {
    const double t = static_cast<double>(k) * dt;
    for (std::size_t u = 0; u < users; ++u) {
      positions[u] = motions[u].position(t);
      server.set_tool(static_cast<int>(u), positions[u]);
    }
    server.step(t);
    for (std::size_t u = 0; u < users; ++u) {
      ForceSample client;
      if (client_ir[u]) {
        const auto& network = std::get<MassSpringIr>(client_ir[u]->ir.body);
        const std::size_t count = network.remote_users.size();
        for (std::size_t r = 0; r < count; ++r)
          remotes[r] = positions[static_cast<std::size_t>(network.remote_users[r])];
        const Stopwatch evaluation;
        client = evaluate_force(*client_ir[u], client_state[u], positions[u],
                                std::span(remotes.data(), count), dt);
        evaluation_us.push_back(1000 * evaluation.elapsed_ms());
      }
      const NetworkToolReaction& reference = server.reaction(static_cast<int>(u));
      const double error = (client.force - reference.force).norm();
      sum_squared += error * error;
      worst = std::max(worst, error);
      if (((client.flags & kInContact) != 0) == reference.colliding)
        worst_agreeing = std::max(worst_agreeing, error);
      row.peak_force = std::max(row.peak_force, reference.force.norm());
    }
    // The IRs cut in this step reach the clients for the next tick.
    for (std::size_t u = 0; u < users; ++u) {
      const std::shared_ptr<const PreparedIR> ir = server.ir(static_cast<int>(u));
      if (!ir || ir == client_ir[u]) continue;
      client_ir[u] = ir;
      client_state[u] = make_evaluation_state(*ir);
      ir_nodes += std::get<MassSpringIr>(ir->ir.body).node_count();
      bytes += static_cast<double>(ir->ir.size_bytes());
      ++row.irs_sent;
    }
  }
  const double peak = std::max(row.peak_force, 1e-300);
  row.error_rms =
      std::sqrt(sum_squared / static_cast<double>(static_cast<std::size_t>(ticks) * users)) / peak;
  row.error_max = worst / peak;
  row.error_max_same_contact = worst_agreeing / peak;
  row.ir_nodes = row.irs_sent > 0 ? ir_nodes / row.irs_sent : 0;
  row.ir_bytes_per_s = bytes / (static_cast<double>(ticks) * dt);
  if (!evaluation_us.empty()) {
    row.evaluation_us = percentile(evaluation_us, 0.5);
    row.evaluation_us_p99 = percentile(evaluation_us, 0.99);
  }
  return row;
}

int run_mass_spring_tradeoff(const Scene& scene, const std::vector<Trajectory>& motions,
                             const TradeoffOptions& options) {
  const std::vector<MassSpringTradeoffSetting> grid = mass_spring_tradeoff_grid(scene);
  std::vector<MassSpringTradeoffRow> rows;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const Stopwatch watch;
    rows.push_back(run_mass_spring_setting(scene, grid[i], motions));
    const MassSpringTradeoffRow& r = rows.back();
    spdlog::info(
        "[{}/{}] sections {}, IR {:g} Hz: error RMS {:.3f} % (max {:.3f} %), {:.0f} nodes per IR, "
        "{:.1f} kB/s, "
        "client {:.2f} µs per tick ({:.1f} s)",
        i + 1, grid.size(), sections_name(r), r.setting.ir_rate_hz, 100 * r.error_rms,
        100 * r.error_max, r.ir_nodes, r.ir_bytes_per_s / 1000, r.evaluation_us,
        watch.elapsed_ms() / 1000);
  }
  std::vector<double> error, bytes, cpu;
  for (const MassSpringTradeoffRow& r : rows) {
    error.push_back(r.error_rms);
    bytes.push_back(r.ir_bytes_per_s);
    cpu.push_back(r.evaluation_us);
  }
  const std::vector<bool> bytes_front = pareto_front(error, bytes),
                          cpu_front = pareto_front(error, cpu);

  AtomicFile csv(options.out / "tradeoff.csv");
  csv.write(
      "sections,ir_rate_hz,ir_nodes,error_rms_pct,error_max_pct,error_max_same_contact_pct,peak_"
      "force_n,evaluation_us_p50,evaluation_us_p99,"
      "ir_bytes_per_s,irs_sent,front_cpu,front_bytes\n");
  AtomicFile md(options.out / "tradeoff.md");
  md.print(
      "# Speed against accuracy: {} (mass-spring)\n\nReference: the server's whole network ({} "
      "nodes) run with "
      "every tool at the haptic rate ({:g} Hz); peak force {:.4f} N. Workload: {}.\n\n"
      "| sections | IR Hz | nodes per IR | error RMS % | error max % | max % where both agree on "
      "contact | client µs "
      "p50 / p99 | IR kB/s | front |\n|---|---|---|---|---|---|---|---|---|\n",
      scene.name, std::get<MassSpringModel>(build_model(scene).bodies.front()).network.node_count(),
      scene.haptic.rate_hz, rows.empty() ? 0.0 : rows.front().peak_force, [&] {
        std::string names;
        for (const auto& file : options.motions)
          names += (names.empty() ? "" : ", ") + file.filename().string();
        return names;
      }());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const MassSpringTradeoffRow& r = rows[i];
    std::string front = cpu_front[i] ? "CPU" : "";
    if (bytes_front[i]) front += front.empty() ? "bytes" : ", bytes";
    csv.print("{},{:g},{:.1f},{:.4g},{:.4g},{:.4g},{:.6g},{:.4g},{:.4g},{:.6g},{},{},{}\n",
              sections_name(r), r.setting.ir_rate_hz, r.ir_nodes, 100 * r.error_rms,
              100 * r.error_max, 100 * r.error_max_same_contact, r.peak_force, r.evaluation_us,
              r.evaluation_us_p99, r.ir_bytes_per_s, r.irs_sent, cpu_front[i] ? 1 : 0,
              bytes_front[i] ? 1 : 0);
    md.print("| {} | {:g} | {:.0f} | {:.3f} | {:.3f} | {:.3f} | {:.2f} / {:.2f} | {:.1f} | {} |\n",
             sections_name(r), r.setting.ir_rate_hz, r.ir_nodes, 100 * r.error_rms,
             100 * r.error_max, 100 * r.error_max_same_contact, r.evaluation_us,
             r.evaluation_us_p99, r.ir_bytes_per_s / 1000, front);
  }
  csv.commit();
  md.commit();
  spdlog::info("wrote {}/tradeoff.csv, tradeoff.md", options.out.string());
  return 0;
}

}  // namespace cohaptic
