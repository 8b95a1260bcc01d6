#include "lab/stability.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "common/haptics/passivity_controller.h"
#include "common/study/measures.h"
#include "common/study/svg_plot.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

// The press: from 5 mm above the wall to 10 mm into it at 10 mm/s, hold, and back.
constexpr double kApproachS = 1.5, kHoldS = 1.5;

Trajectory wall_press() {
  const Eigen::Vector3d above(0, 0, 0.005), deep(0, 0, -0.010);
  return Trajectory({0.0, kApproachS, kApproachS + kHoldS, 2 * kApproachS + kHoldS},
                    {above, deep, deep, above}, "wall press");
}

Eigen::Vector3d wall_force(double stiffness, const Eigen::Vector3d& position) {
  return Eigen::Vector3d(0, 0, stiffness * std::max(0.0, -position.z()));
}

}  // namespace

WallLoopResult run_wall_loop(const WallLoopSettings& settings) {
  if (!(settings.stiffness_n_per_m > 0) || !(settings.haptic_rate_hz > 0) ||
      !(settings.shift_delay_s >= 0) || !(settings.step_period_s >= 0))
    throw Error("run_wall_loop: stiffness and haptic rate must be positive, delays non-negative");
  const Trajectory motion = wall_press();
  HandModelDevice hand(motion, settings.hand, settings.force_limit_n);
  // The hand is the only mass at the tool; the controller limits its own output.
  PassivityController controller(settings.hand.mass_kg, settings.force_limit_n);
  const double period = 1 / settings.haptic_rate_hz;
  const auto ticks = static_cast<std::size_t>(std::ceil(motion.duration() / period)) + 1;
  WallLoopResult result;
  std::vector<Eigen::Vector3d> positions;  // per tick
  positions.reserve(ticks);
  for (std::size_t k = 0; k < ticks; ++k) {
    const double t = static_cast<double>(k) * period;
    const Eigen::Vector3d x = hand.read(t).position;
    positions.push_back(x);
    // The moment whose position the environment's current answer was computed from.
    double seen = t - settings.shift_delay_s;
    if (settings.step_period_s > 0)
      seen = std::floor(seen / settings.step_period_s + 1e-9) * settings.step_period_s -
             settings.step_period_s;
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    if (seen >= 0) {
      const auto index = std::min(k, static_cast<std::size_t>(std::floor(seen / period + 1e-9)));
      force = wall_force(settings.stiffness_n_per_m, positions[index]);
    }
    if (settings.passivity_control) force = controller.filter(t, x, force);
    if (force.norm() > settings.force_limit_n) force *= settings.force_limit_n / force.norm();
    hand.write_force(force, t);
    result.trace.time_s.push_back(t);
    result.trace.force.push_back(force);
    result.trace.position.push_back(x);
    result.peak_force_n = std::max(result.peak_force_n, force.norm());
  }
  result.energy_given_to_hand_j = energy_given_to_hand(result.trace);
  const double hold_end = kApproachS + kHoldS;
  for (const OscillationEpisode& episode : find_oscillations(result.trace))
    if (episode.end_s >= hold_end - 0.5 && episode.begin_s <= hold_end) result.oscillating = true;
  result.controller_ticks = controller.active_ticks();
  result.dissipated_j = controller.dissipated_energy();
  return result;
}

double passivity_bound(const WallLoopSettings& settings) {
  const double period = 1 / settings.haptic_rate_hz;
  const double hold = std::max(period, settings.step_period_s);
  const double latency = settings.shift_delay_s + settings.step_period_s;
  return settings.hand.damping_ns_per_m / (hold / 2 + latency);
}

namespace {

struct MapRow {
  WallLoopSettings settings;
  WallLoopResult plain, controlled;
  double transparency_cost = 0;  // RMS |F_controlled - F_plain| over the plain run's peak
};

double rms_difference(const ForceTrace& a, const ForceTrace& b, double peak) {
  double sum = 0;
  const std::size_t n = std::min(a.size(), b.size());
  for (std::size_t k = 0; k < n; ++k) sum += (a.force[k] - b.force[k]).squaredNorm();
  return n && peak > 0 ? std::sqrt(sum / static_cast<double>(n)) / peak : 0;
}

const char* verdict(const WallLoopResult& r) {
  return r.stable() ? "stable" : r.passive() ? "oscillating" : "active";
}

// The largest stiffness in `rows` (same delays and rate) below which every run is stable.
double stable_limit(const std::vector<const MapRow*>& rows, bool controlled) {
  double limit = 0;
  for (const MapRow* row : rows) {
    if (!(controlled ? row->controlled : row->plain).stable()) break;
    limit = row->settings.stiffness_n_per_m;
  }
  return limit;
}

}  // namespace

int run_stability(const StabilityOptions& options) {
  validate_hand_parameters(options.hand);
  std::filesystem::create_directories(options.out);
  const std::vector<double> stiffnesses = {500, 1000, 2000, 4000, 8000, 16000, 32000, 64000};
  const std::vector<double> rates = {500, 1000, 2000, 5000};
  // (shift delay, step period) pairs: shift delay alone, then step delay alone.
  const std::vector<std::pair<double, double>> delays = {
      {0, 0}, {0.002, 0}, {0.005, 0}, {0.010, 0}, {0.020, 0}, {0, 0.010}, {0, 0.040}};
  std::vector<MapRow> rows;
  for (const auto& [shift, step] : delays)
    for (double rate : rates)
      for (double stiffness : stiffnesses) {
        MapRow row;
        row.settings.stiffness_n_per_m = stiffness;
        row.settings.haptic_rate_hz = rate;
        row.settings.shift_delay_s = shift;
        row.settings.step_period_s = step;
        row.settings.hand = options.hand;
        row.plain = run_wall_loop(row.settings);
        WallLoopSettings controlled = row.settings;
        controlled.passivity_control = true;
        row.controlled = run_wall_loop(controlled);
        row.transparency_cost =
            rms_difference(row.controlled.trace, row.plain.trace, row.plain.peak_force_n);
        rows.push_back(std::move(row));
      }
  spdlog::info("stability: {} configurations, each with and without the passivity controller",
               rows.size());

  AtomicFile csv(options.out / "stability.csv");
  csv.write(
      "stiffness_n_per_m,haptic_rate_hz,shift_delay_ms,step_period_ms,passivity_bound_n_per_m,"
      "energy_given_j,"
      "oscillating,verdict,controlled_energy_given_j,controlled_oscillating,controlled_verdict,"
      "controller_ticks,"
      "dissipated_j,transparency_cost\n");
  for (const MapRow& r : rows)
    csv.print("{:g},{:g},{:g},{:g},{:.6g},{:.6g},{},{},{:.6g},{},{},{},{:.6g},{:.6g}\n",
              r.settings.stiffness_n_per_m, r.settings.haptic_rate_hz,
              1000 * r.settings.shift_delay_s, 1000 * r.settings.step_period_s,
              passivity_bound(r.settings), r.plain.energy_given_to_hand_j,
              r.plain.oscillating ? 1 : 0, verdict(r.plain), r.controlled.energy_given_to_hand_j,
              r.controlled.oscillating ? 1 : 0, verdict(r.controlled),
              r.controlled.controller_ticks, r.controlled.dissipated_j, r.transparency_cost);
  csv.commit();

  AtomicFile md(options.out / "stability.md");
  md.print(
      "# Stability of a virtual wall under the hand model (m {} kg, k {} N/m, c {} N s/m)\n\n"
      "Each cell: the verdict without / with the passivity controller: S stable, o passive but "
      "oscillating, "
      "a active (the wall gave the hand more than 1 mJ). *bound* is the first-order passivity "
      "bound "
      "c / (T_hold/2 + latency) [N/m]; *stable up to* the largest K with every smaller K stable "
      "(without / with the "
      "controller).\n\n| delay | rate Hz | bound |",
      options.hand.mass_kg, options.hand.stiffness_n_per_m, options.hand.damping_ns_per_m);
  for (double k : stiffnesses) md.print(" {:g} |", k);
  md.write(" stable up to |\n|---|---|---|");
  for (std::size_t i = 0; i <= stiffnesses.size(); ++i) md.write("---|");
  md.write("\n");
  const auto letter = [](const WallLoopResult& r) {
    return r.stable() ? "S" : r.passive() ? "o" : "a";
  };
  LinePlot plot;
  plot.title = "Largest stable wall stiffness (measured, with markers) and the passivity bound";
  plot.x_label = "haptic rate, Hz";
  plot.y_label = "stiffness, kN/m";
  for (const auto& [shift, step] : delays) {
    const std::string label = step > 0 ? fmt::format("step {:g} ms", 1000 * step)
                                       : fmt::format("shift {:g} ms", 1000 * shift);
    Series measured{label, {}, {}, "", true};
    Series bound_line{label + " bound", {}, {}, "", false};
    for (double rate : rates) {
      std::vector<const MapRow*> same;
      for (const MapRow& r : rows)
        if (r.settings.shift_delay_s == shift && r.settings.step_period_s == step &&
            r.settings.haptic_rate_hz == rate)
          same.push_back(&r);
      const double limit = stable_limit(same, false), controlled_limit = stable_limit(same, true);
      const double bound = passivity_bound(same.front()->settings);
      md.print("| {} | {:g} | {:.0f} |", label, rate, bound);
      for (const MapRow* r : same) md.print(" {}/{} |", letter(r->plain), letter(r->controlled));
      md.print(" {:g} / {:g} |\n", limit, controlled_limit);
      measured.x.push_back(rate);
      measured.y.push_back(limit / 1000);
      bound_line.x.push_back(rate);
      bound_line.y.push_back(std::min(bound, stiffnesses.back()) / 1000);
    }
    plot.series.push_back(measured);
    plot.series.push_back(bound_line);
  }
  std::vector<double> costs;
  for (const MapRow& r : rows)
    if (r.plain.stable()) costs.push_back(r.transparency_cost);
  std::sort(costs.begin(), costs.end());
  int rescued = 0, made_passive = 0, unstable = 0;
  for (const MapRow& r : rows)
    if (!r.plain.stable()) {
      ++unstable;
      rescued += r.controlled.stable();
      made_passive += !r.plain.passive() && r.controlled.passive();
    }
  md.print(
      "\nThe passivity controller makes {} of the {} unstable configurations stable, and {} active "
      "ones passive. "
      "Where the loop was already stable ({} configurations) it changes the force by {:.2f} % of "
      "the peak (RMS, "
      "median; largest {:.2f} %): it acts only once the wall has given out more than its tolerance "
      "(0.1 mJ).\n",
      rescued, unstable, made_passive, costs.size(),
      costs.empty() ? 0.0 : 100 * costs[costs.size() / 2],
      costs.empty() ? 0.0 : 100 * costs.back());
  md.commit();
  write_svg(options.out / "stability.svg", plot);
  spdlog::info(
      "passivity controller: {} of {} unstable configurations made stable; cost where stable: "
      "median {:.2f} %",
      rescued, unstable, costs.empty() ? 0.0 : 100 * costs[costs.size() / 2]);
  spdlog::info("wrote {}/stability.csv, stability.md, stability.svg", options.out.string());
  return 0;
}

LabCommand add_stability_command(CLI::App& lab) {
  auto options = std::make_shared<StabilityOptions>();
  CLI::App* command = lab.add_subcommand(
      "stability",
      "Map where a virtual wall stays stable under the hand model (stiffness x haptic rate x "
      "delay), with "
      "and without the passivity controller: stability.csv, stability.md, stability.svg in --out");
  command->add_option("--out", options->out, "Output directory")->required();
  command->add_option("--hand-mass", options->hand.mass_kg, "Hand model mass [kg]")
      ->capture_default_str();
  command
      ->add_option("--hand-stiffness", options->hand.stiffness_n_per_m,
                   "Hand model stiffness [N/m]")
      ->capture_default_str();
  command
      ->add_option("--hand-damping", options->hand.damping_ns_per_m, "Hand model damping [N s/m]")
      ->capture_default_str();
  return {command, [options] { return run_stability(*options); }};
}

}  // namespace cohaptic
