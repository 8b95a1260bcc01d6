#include "lab/separation_pull.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <utility>
#include <fstream>
#include <numbers>

#include "common/model/model.h"
#include "common/scene/load_scene.h"
#include "common/separation/pull_loop_figure.h"
#include "common/separation/separation_setup.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

// The separation body whose interface has the node nearest `point` [m], and that node.
std::pair<const SeparationModel*, int> nearest_separation_node(const Model& model,
                                                               const Eigen::Vector3d& point) {
  std::pair<const SeparationModel*, int> nearest{nullptr, -1};
  double best = INFINITY;
  for (const BodyModel& body : model.bodies)
    if (const auto* separation = std::get_if<SeparationModel>(&body)) {
      const int node = nearest_patch_node(*separation->patch, point);
      if (const double distance = (separation->patch->positions.col(node) - point).norm();
          distance < best) {
        best = distance;
        nearest = {separation, node};
      }
    }
  if (!nearest.first)
    throw Error(fmt::format("scene '{}' has no object of model: separation", model.scene.name));
  return nearest;
}

void write_separation_pull_csv(const std::filesystem::path& file, const PullLoop& loop) {
  std::ofstream out(file);
  if (!out) throw Error(fmt::format("cannot write {}", file.string()));
  out << "time_s,travel_mm,force_N,normal_force_N,separated_area_mm2,local_separated,phase\n";
  for (const PullLoopSample& s : loop.samples)
    out << fmt::format("{:.6f},{:.6f},{:.9f},{:.9f},{:.9f},{:.9f},{}\n", s.time, 1e3 * s.travel,
                       s.force, s.normal_force, 1e6 * s.separated_area, s.local_separated,
                       static_cast<char>(s.phase));
}

}  // namespace

int run_separation_pull(const SeparationPullOptions& options) {
  Scene scene = load_scene(options.scene);
  if (!options.disk_cache) use_separation_field_cache(scene, std::nullopt);
  const Model model = build_model(scene);
  const auto [body, node_index] = nearest_separation_node(
      model, Eigen::Vector3d(1e-3 * options.at_mm.at(0), 1e-3 * options.at_mm.at(1), 0));
  const SeparationPatch& patch = *body->patch;

  PullLoopSettings settings;
  settings.node = node_index;
  const double tilt = options.tilt_deg * std::numbers::pi / 180;
  const Eigen::Vector3d n =
      patch.normals[static_cast<std::size_t>(patch.regions.of(settings.node).front())];
  const Eigen::Vector3d along_x =
      (Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitX().dot(n) * n).normalized();
  settings.direction = std::cos(tilt) * n + std::sin(tilt) * along_x;
  settings.speed = 1e-3 * options.speed_mm_s;
  const PullLoop loop = run_pull_loop(patch, make_separation_state(patch), settings);

  double bc_low = INFINITY, bc_high = -INFINITY, bc_travel = 0;
  const PullLoopSample* previous = nullptr;
  for (const PullLoopSample& s : loop.samples) {
    if (s.phase == PullPhase::fracture) {
      bc_low = std::min(bc_low, s.force);
      bc_high = std::max(bc_high, s.force);
      if (previous) bc_travel += s.travel - previous->travel;
    }
    previous = &s;
  }
  const Eigen::Vector3d node = patch.positions.col(settings.node);
  fmt::print(
      "Fig. 10 pull on '{}' at node {} ({:.1f}, {:.1f}) mm, {:.1f} mm/s, {:.0f} deg from the "
      "normal:\n",
      body->name, settings.node, 1e3 * node.x(), 1e3 * node.y(), options.speed_mm_s,
      options.tilt_deg);
  fmt::print(
      "  threshold J_c l = {:.4f} N; BC held between {:.4f} and {:.4f} N ({:+.2f} % .. {:+.2f} "
      "%)\n",
      loop.threshold, bc_low, bc_high, 100 * (bc_low / loop.threshold - 1),
      100 * (bc_high / loop.threshold - 1));
  fmt::print(
      "  BC: {:.3f} mm of travel, {:.3f} mm^2 separated (l_n dz = {:.3f} mm^2 for the normal "
      "part)\n",
      1e3 * bc_travel, 1e6 * loop.fracture_area, 1e6 * patch.normal_length * loop.fracture_travel);
  fmt::print(
      "  work in BC {:.4e} J against J_c dLambda = {:.4e} J ({:+.2f} %); net work over the loop "
      "{:.4e} J (>= 0: passive)\n",
      loop.fracture_work, patch.toughness * loop.fracture_area,
      100 * (loop.fracture_work / (patch.toughness * loop.fracture_area) - 1), loop.net_work);
  fmt::print("  turned back at {:.3f} mm; {} samples\n", 1e3 * loop.turn_travel,
             loop.samples.size());
  if (!options.out.empty()) {
    std::filesystem::create_directories(options.out);
    write_svg(options.out / "fig10_force.svg", pull_loop_force_plot(loop));
    write_svg(options.out / "fig10_area.svg", pull_loop_area_plot(loop, patch.interface_area));
    write_separation_pull_csv(options.out / "pull_loop.csv", loop);
    spdlog::info("wrote fig10_force.svg, fig10_area.svg and pull_loop.csv to {}",
                 options.out.string());
  }
  return 0;
}

LabCommand add_separation_pull_command(CLI::App& lab) {
  auto options = std::make_shared<SeparationPullOptions>();
  CLI::App* command = lab.add_subcommand(
      "separation-pull",
      "The separation-forces paper's Fig. 10 on a scene's separating interface: a grasp pulls a "
      "node "
      "away and back; prints the thresholds and the energy balance, writes the figures to --out");
  command->add_option("--scene", options->scene, "A scene with an object of model: separation")
      ->capture_default_str();
  command
      ->add_option(
          "--at", options->at_mm,
          "Hold the interface node nearest (x, y, 0) [mm], on whichever separation object has it")
      ->expected(2)
      ->capture_default_str();
  command->add_option("--speed", options->speed_mm_s, "Pull speed [mm/s]")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 1000.0));
  command
      ->add_option("--tilt", options->tilt_deg,
                   "Pull direction's angle from the normal towards +x [deg]")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 89.0));
  command->add_option("--out", options->out,
                      "Write fig10_force.svg, fig10_area.svg and pull_loop.csv here");
  command->add_flag(
      "--no-disk-cache", [options](std::int64_t) { options->disk_cache = false; },
      "Fit the fields without reading or writing the cache");
  return {command, [options] { return run_separation_pull(*options); }};
}

}  // namespace cohaptic
