#include "lab/objects_push.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cstdio>

#include "common/scene/load_scene.h"
#include "common/study/svg_plot.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"
#include "lab/push_in_time.h"

namespace cohaptic {

std::string paired_boxes_scene_yaml(const PairedBoxesOptions& o) {
  const auto divisions = [](const Eigen::Vector3i& d) {
    return fmt::format("[{}, {}, {}]", d.x(), d.y(), d.z());
  };
  return fmt::format(R"(
units: mm
objects:
  - name: front
    mesh: {{box: {{min: [{0}, 15.95, 0], size: [57.5, 98.9, 57.5], divisions: {1}}}}}
    material: {{youngs_modulus: 1.0e5, poisson_ratio: 0.3}}
    fixed: [{{plane: {{point: [0, 0, 0], normal: [0, 0, 1]}}}}]
    compliance: {{precompute: on_demand, disk_cache: false}}
  - name: behind
    mesh: {{box: {{min: [0, 0, 0], size: [86.5, 130.8, 108.7], divisions: {2}}}}}
    material: {{youngs_modulus: {3}, poisson_ratio: {4}}}
    fixed: [{{plane: {{point: [0, 0, 0], normal: [0, 0, 1]}}}}, {{plane: {{point: [86.5, 0, 0], normal: [1, 0, 0]}}}}]
    touchable: [{{plane: {{point: [0, 0, 0], normal: [1, 0, 0]}}}}]
    compliance: {{precompute: on_demand, disk_cache: false}}
tools: [{{name: A}}]
)",
                     -57.5 - o.gap_mm, divisions(o.front_divisions), divisions(o.behind_divisions),
                     o.behind_youngs_modulus, o.behind_poisson_ratio);
}

PushLayout push_layout(const Scene& scene) {
  const std::string where = scene.file.empty() ? scene.name : scene.file.string();
  if (scene.interactions.size() != 1)
    throw Error(
        fmt::format("objects-push: {} has {} interactions; the pushing test needs exactly one (A "
                    "in front of B)",
                    where, scene.interactions.size()));
  PushLayout layout;
  for (int i = 0; i < static_cast<int>(scene.objects.size()); ++i) {
    if (scene.objects[static_cast<std::size_t>(i)].name == scene.interactions[0].front)
      layout.front = i;
    if (scene.objects[static_cast<std::size_t>(i)].name == scene.interactions[0].behind)
      layout.behind = i;
  }
  const auto* front = std::get_if<MassSpringObjectSpec>(
      &scene.objects.at(static_cast<std::size_t>(layout.front)).body);
  const auto* behind = std::get_if<ElasticObjectSpec>(
      &scene.objects.at(static_cast<std::size_t>(layout.behind)).body);
  if (!front || !front->lattice || !behind || !behind->mesh.box)
    throw Error(fmt::format(
        "objects-push: in {}, the interaction's front object must be a mass-spring lattice and its "
        "behind object a linear elastic box (mesh: box)",
        where));
  const SpringLatticeSpec& a = *front->lattice;
  const BoxMeshSpec& b = *behind->mesh.box;
  const Eigen::Vector3d towards = (b.min_corner + b.size / 2) - (a.min_corner + a.size / 2);
  towards.cwiseAbs().cwiseQuotient(a.size + b.size).maxCoeff(&layout.axis);
  if (towards[layout.axis] <= 0)
    throw Error(fmt::format(
        "objects-push: in {}, B must lie on the + side of A along the axis joining them", where));
  layout.back = a.min_corner[layout.axis] + a.size[layout.axis];
  return layout;
}

Scene push_scene(Scene scene, const PushVariation& variation) {
  const PushLayout layout = push_layout(scene);
  auto& behind =
      std::get<ElasticObjectSpec>(scene.objects[static_cast<std::size_t>(layout.behind)].body);
  behind.material.youngs_modulus = variation.behind_youngs_modulus;
  behind.material.poisson_ratio = variation.behind_poisson_ratio;
  if (variation.condition == BackCondition::on_behind) return scene;
  scene.interactions.clear();
  if (variation.condition == BackCondition::fixed) {
    NodeSelector back;
    back.kind = NodeSelector::Kind::plane;
    back.plane_point = Eigen::Vector3d::Zero();
    back.plane_point[layout.axis] = layout.back;
    back.plane_normal = Eigen::Vector3d::Unit(layout.axis);
    back.where =
        fmt::format("objects-push: A's back face ({} = {} m)", "xyz"[layout.axis], layout.back);
    std::get<MassSpringObjectSpec>(scene.objects[static_cast<std::size_t>(layout.front)].body)
        .fixed.push_back(back);
  }
  return scene;
}

Eigen::Vector3d push_point(const Scene& scene, const PushLayout& layout) {
  const SpringLatticeSpec& a =
      *std::get<MassSpringObjectSpec>(scene.objects[static_cast<std::size_t>(layout.front)].body)
           .lattice;
  Eigen::Vector3d point = a.min_corner + a.size / 2;
  point[layout.axis] = a.min_corner[layout.axis];
  return point;
}

namespace {

// A as the quasi-static solve takes it: its network's springs at rest, its held nodes fixed.
PushedFront spring_front(const MassSpringModel& body, const PushLayout& layout,
                         const Eigen::Vector3d& point) {
  const MassSpringNetwork& network = body.network;
  PushedFront front;
  front.rest_positions = network.rest_positions;
  front.springs = network.springs;
  for (std::uint8_t held : network.held) front.fixed_axes.push_back(held ? kAllAxes : AxisMask{0});
  front.surface = make_surface_adjacency(network.triangles, network.node_count());
  double nearest = INFINITY;
  for (int node : network.surface_nodes) {
    const Eigen::Vector3d x = network.rest_positions.col(node);
    if (x[layout.axis] > layout.back - 1e-9) front.back_face.push_back(node);
    if ((x - point).norm() < nearest) {
      nearest = (x - point).norm();
      front.tool_node = node;
    }
  }
  front.push_axis = layout.axis;
  return front;
}

}  // namespace

PushRig::PushRig(const Scene& scene, const PushVariation& variation)
    : model(std::make_unique<Model>(
          build_model(push_scene(scene, {BackCondition::on_behind, variation.behind_youngs_modulus,
                                         variation.behind_poisson_ratio})))),
      layout(push_layout(scene)),
      front(spring_front(
          std::get<MassSpringModel>(model->bodies[static_cast<std::size_t>(layout.front)]), layout,
          push_point(scene, layout))),
      behind_surface(
          make_surface_adjacency(behind().surface.triangles, behind().mesh.node_count())),
      behind_columns(std::make_unique<ComplianceColumns>(behind().free_factor, behind().dofs,
                                                         behind().surface.nodes)) {}

const ElasticBody& PushRig::behind() const { return elastic_body(*model, layout.behind); }

std::vector<double> paper_push_depths() {
  std::vector<double> depths;
  for (int mm = 1; mm <= 15; ++mm) depths.push_back(1e-3 * mm);
  return depths;
}

std::vector<double> push_forces(PushRig& rig, BackCondition condition,
                                const std::vector<double>& depths) {
  BehindBody behind = rig.behind_body();
  std::vector<double> forces;
  for (const PushSample& sample : push_front(rig.front, condition, &behind, depths))
    forces.push_back(sample.force);
  return forces;
}

namespace {

struct Curve {
  std::string figure;  // conditions, youngs, poisson
  std::string label;
  PushVariation variation;
  std::vector<double> forces;             // quasi-static, at the depths
  std::vector<PushInTimeSample> in_time;  // every server step (--in-time)
  std::vector<double> in_time_forces;     // at the depths (--in-time)
  std::vector<double>
      nonlinear_forces;  // A's nonlinear equilibrium at the depths (--in-time; not on B)
};

void write_push_figures(const std::filesystem::path& out, const std::vector<Curve>& curves,
                        const std::vector<double>& depths, bool in_time) {
  const std::pair<const char*, const char*> figures[] = {
      {"conditions", "The force under three conditions (Fig. 6)"},
      {"youngs", "On B: the force with B's Young's modulus (Fig. 7)"},
      {"poisson", "On B: the force with B's Poisson ratio (Fig. 8)"}};
  for (const auto& [figure, title] : figures) {
    LinePlot plot;
    plot.title = in_time ? fmt::format("{}, pushed at 5 mm/s", title) : title;
    plot.x_label = "depth, mm";
    plot.y_label = "force, N";
    for (const Curve& c : curves) {
      if (c.figure != figure) continue;
      Series series{c.label, {}, {}, "", true};
      for (std::size_t i = 0; i < depths.size(); ++i) {
        series.x.push_back(1e3 * depths[i]);
        series.y.push_back(in_time ? c.in_time_forces[i] : c.forces[i]);
      }
      plot.series.push_back(std::move(series));
    }
    write_svg(out / fmt::format("objects_push{}_{}.svg", in_time ? "_in_time" : "", figure), plot);
  }
}

// In time beside quasi-static at 5, 10 and 15 mm, and every server step of every curve.
void write_in_time_results(const std::filesystem::path& out, const std::vector<Curve>& curves) {
  AtomicFile csv(out / "objects_push_in_time.csv");
  csv.write(
      "figure,curve,condition,behind_youngs_modulus_pa,behind_poisson_ratio,time_s,depth_mm,force_"
      "n\n");
  for (const Curve& c : curves)
    for (const PushInTimeSample& s : c.in_time)
      csv.print("{},{},{},{:g},{:g},{:g},{:.6g},{:.9g}\n", c.figure, c.label,
                back_condition_name(c.variation.condition), c.variation.behind_youngs_modulus,
                c.variation.behind_poisson_ratio, s.time, 1e3 * s.depth, s.force);
  csv.commit();
  std::string table =
      "| figure | curve | depth [mm] | in time [N] | nonlinear static [N] | linear quasi-static "
      "[N] |\n"
      "|---|---|---|---|---|---|\n";
  for (const Curve& c : curves)
    for (std::size_t i : {std::size_t{0}, std::size_t{4}, std::size_t{9}, std::size_t{14}}) {
      const std::string nonlinear =
          c.nonlinear_forces.empty()
              ? "-"
              : fmt::format("{:.5f} ({:+.2f} %)", c.nonlinear_forces[i],
                            100 * (c.in_time_forces[i] / c.nonlinear_forces[i] - 1));
      table += fmt::format("| {} | {} | {} | {:.5f} | {} | {:.5f} ({:+.2f} %) |\n", c.figure,
                           c.label, i + 1, c.in_time_forces[i], nonlinear, c.forces[i],
                           100 * (c.in_time_forces[i] / c.forces[i] - 1));
    }
  AtomicFile md(out / "objects_push_in_time.md");
  md.print(
      "# The several-objects pushing test in time (5 mm/s) beside the static solves\n\n"
      "In brackets: the in-time force's difference from each.\n\n{}",
      table);
  md.commit();
  std::fputs(table.c_str(), stdout);
}

}  // namespace

int run_objects_push(const ObjectsPushOptions& options) {
  const Scene scene = load_scene(options.scene);
  const std::vector<double> depths = paper_push_depths();
  std::vector<Curve> curves;
  const auto run = [&](std::string figure, std::string label, PushVariation variation) {
    PushRig rig(scene, variation);
    Curve curve{std::move(figure),
                std::move(label),
                variation,
                push_forces(rig, variation.condition, depths),
                {},
                {},
                {}};
    if (options.in_time) {
      curve.in_time = push_in_time(scene, variation);
      curve.in_time_forces = forces_at_depths(curve.in_time, depths);
      if (variation.condition != BackCondition::on_behind)
        curve.nonlinear_forces = network_static_forces(scene, variation, depths);
    }
    spdlog::info(
        "objects-push: {} {}: {:.4f} N at 15 mm{}", curve.figure, curve.label, curve.forces.back(),
        options.in_time ? fmt::format(", {:.4f} N in time", curve.in_time_forces.back()) : "");
    curves.push_back(std::move(curve));
  };
  run("conditions", "1: back free", {BackCondition::free, 1.0e6, 0.216});
  run("conditions", "3: on B", {BackCondition::on_behind, 1.0e6, 0.216});
  run("conditions", "2: back fixed", {BackCondition::fixed, 1.0e6, 0.216});
  for (double e : {1.0e6, 1.5e6, 2.0e6})
    run("youngs", fmt::format("E_B {:.1f} MPa", 1e-6 * e), {BackCondition::on_behind, e, 0.216});
  for (double nu : {0.108, 0.162, 0.216})
    run("poisson", fmt::format("nu_B {:.3f}", nu), {BackCondition::on_behind, 1.0e6, nu});

  std::filesystem::create_directories(options.out);
  AtomicFile csv(options.out / "objects_push.csv");
  csv.write(
      "figure,curve,condition,behind_youngs_modulus_pa,behind_poisson_ratio,depth_mm,force_n\n");
  for (const Curve& c : curves)
    for (std::size_t i = 0; i < depths.size(); ++i)
      csv.print("{},{},{},{:g},{:g},{:g},{:.9g}\n", c.figure, c.label,
                back_condition_name(c.variation.condition), c.variation.behind_youngs_modulus,
                c.variation.behind_poisson_ratio, 1e3 * depths[i], c.forces[i]);
  csv.commit();

  std::string table =
      "| figure | curve | F at 5 mm [N] | F at 10 mm [N] | F at 15 mm [N] "
      "|\n|---|---|---|---|---|\n";
  for (const Curve& c : curves)
    table += fmt::format("| {} | {} | {:.5f} | {:.5f} | {:.5f} |\n", c.figure, c.label, c.forces[4],
                         c.forces[9], c.forces[14]);
  AtomicFile md(options.out / "objects_push.md");
  md.print("# The several-objects pushing test (quasi-static)\n\n{}", table);
  md.commit();
  std::fputs(table.c_str(), stdout);
  write_push_figures(options.out, curves, depths, false);
  if (options.in_time) {
    write_in_time_results(options.out, curves);
    write_push_figures(options.out, curves, depths, true);
  }
  spdlog::info("objects-push: wrote objects_push.csv, objects_push.md and three figures{} in {}",
               options.in_time ? ", and their in-time twins" : "", options.out.string());
  return 0;
}

LabCommand add_objects_push_command(CLI::App& lab) {
  auto options = std::make_shared<ObjectsPushOptions>();
  CLI::App* command =
      lab.add_subcommand("objects-push",
                         "The several-objects paper's pushing test: the front box pushed 1-15 mm "
                         "with its back free, fixed or on the "
                         "elastic box behind it, and on B with three Young's moduli and Poisson "
                         "ratios: objects_push.csv, "
                         "objects_push.md, objects_push_{conditions,youngs,poisson}.svg in --out");
  command->add_option("--scene", options->scene, "The test's scene (condition 3)")
      ->capture_default_str();
  command->add_option("--out", options->out, "Output directory")->required();
  command->add_flag("--in-time", options->in_time,
                    "Also push 15 mm at 5 mm/s through the server's simulation: "
                    "objects_push_in_time.{csv,md} and "
                    "objects_push_in_time_{conditions,youngs,poisson}.svg");
  return {command, [options] { return run_objects_push(*options); }};
}

}  // namespace cohaptic
