#include "lab/objects_push.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cstdio>

#include "common/mass_spring/springs_along_edges.h"
#include "common/scene/load_scene.h"
#include "common/study/svg_plot.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"

namespace cohaptic {

std::string paired_boxes_scene_yaml(const PairedBoxesOptions& o) {
  const auto divisions = [](const Eigen::Vector3i& d) { return fmt::format("[{}, {}, {}]", d.x(), d.y(), d.z()); };
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

namespace {

PushedFront spring_front(const ElasticBody& body, const PushRigOptions& options) {
  PushedFront front;
  front.rest_positions = body.mesh.nodes;
  front.springs = springs_along_edges(body.mesh, options.spring_stiffness, options.spring_damping);
  front.fixed_axes = body.dofs.fixed_axes;
  front.surface = make_surface_adjacency(body.surface.triangles, body.mesh.node_count());
  const double back_x = body.mesh.nodes.row(0).maxCoeff();
  const double front_x = body.mesh.nodes.row(0).minCoeff();
  const Eigen::Vector2d centre = 0.5 * (body.mesh.nodes.bottomRows<2>().rowwise().minCoeff() +
                                        body.mesh.nodes.bottomRows<2>().rowwise().maxCoeff());
  double nearest = INFINITY;
  for (int node : body.surface.nodes) {
    const Eigen::Vector3d x = body.mesh.nodes.col(node);
    if (x.x() > back_x - 1e-9) front.back_face.push_back(node);
    if (x.x() < front_x + 1e-9 && (x.tail<2>() - centre).norm() < nearest) {
      nearest = (x.tail<2>() - centre).norm();
      front.tool_node = node;
    }
  }
  front.push_axis = 0;
  return front;
}

}  // namespace

PushRig::PushRig(const PushRigOptions& options)
    : model(std::make_unique<Model>(build_model(parse_scene(paired_boxes_scene_yaml(options.boxes), "paired-boxes.yaml")))),
      front(spring_front(elastic_body(*model, 0), options)),
      behind_surface(make_surface_adjacency(behind().surface.triangles, behind().mesh.node_count())),
      behind_columns(std::make_unique<ComplianceColumns>(*behind().free_factor, behind().dofs, behind().surface.nodes)) {}

const ElasticBody& PushRig::behind() const { return elastic_body(*model, 1); }

std::vector<double> paper_push_depths() {
  std::vector<double> depths;
  for (int mm = 1; mm <= 15; ++mm) depths.push_back(1e-3 * mm);
  return depths;
}

std::vector<double> push_forces(PushRig& rig, BackCondition condition, const std::vector<double>& depths) {
  BehindBody behind = rig.behind_body();
  std::vector<double> forces;
  for (const PushSample& sample : push_front(rig.front, condition, &behind, depths)) forces.push_back(sample.force);
  return forces;
}

namespace {

struct Curve {
  std::string figure;  // conditions, youngs, poisson
  std::string label;
  BackCondition condition;
  double youngs_modulus, poisson_ratio;
  std::vector<double> forces;
};

}  // namespace

int run_objects_push(const ObjectsPushOptions& options) {
  const std::vector<double> depths = paper_push_depths();
  std::vector<Curve> curves;
  const auto run = [&](std::string figure, std::string label, BackCondition condition, double e, double nu) {
    PushRigOptions rig_options;
    rig_options.boxes.behind_youngs_modulus = e;
    rig_options.boxes.behind_poisson_ratio = nu;
    PushRig rig(rig_options);
    curves.push_back({std::move(figure), std::move(label), condition, e, nu, push_forces(rig, condition, depths)});
    spdlog::info("objects-push: {} {}: {:.4f} N at 15 mm", curves.back().figure, curves.back().label,
                 curves.back().forces.back());
  };
  run("conditions", "1: back free", BackCondition::free, 1.0e6, 0.216);
  run("conditions", "3: on B", BackCondition::on_behind, 1.0e6, 0.216);
  run("conditions", "2: back fixed", BackCondition::fixed, 1.0e6, 0.216);
  for (double e : {1.0e6, 1.5e6, 2.0e6})
    run("youngs", fmt::format("E_B {:.1f} MPa", 1e-6 * e), BackCondition::on_behind, e, 0.216);
  for (double nu : {0.108, 0.162, 0.216})
    run("poisson", fmt::format("nu_B {:.3f}", nu), BackCondition::on_behind, 1.0e6, nu);

  std::filesystem::create_directories(options.out);
  AtomicFile csv(options.out / "objects_push.csv");
  csv.write("figure,curve,condition,behind_youngs_modulus_pa,behind_poisson_ratio,depth_mm,force_n\n");
  for (const Curve& c : curves)
    for (std::size_t i = 0; i < depths.size(); ++i)
      csv.print("{},{},{},{:g},{:g},{:g},{:.9g}\n", c.figure, c.label, back_condition_name(c.condition),
                c.youngs_modulus, c.poisson_ratio, 1e3 * depths[i], c.forces[i]);
  csv.commit();

  std::string table =
      "| figure | curve | F at 5 mm [N] | F at 10 mm [N] | F at 15 mm [N] |\n|---|---|---|---|---|\n";
  for (const Curve& c : curves)
    table += fmt::format("| {} | {} | {:.5f} | {:.5f} | {:.5f} |\n", c.figure, c.label, c.forces[4], c.forces[9],
                         c.forces[14]);
  AtomicFile md(options.out / "objects_push.md");
  md.print("# The several-objects pushing test (quasi-static)\n\n{}", table);
  md.commit();
  std::fputs(table.c_str(), stdout);

  const std::pair<const char*, const char*> figures[] = {
      {"conditions", "The force under three conditions (Fig. 6)"},
      {"youngs", "On B: the force with B's Young's modulus (Fig. 7)"},
      {"poisson", "On B: the force with B's Poisson ratio (Fig. 8)"}};
  for (const auto& [figure, title] : figures) {
    LinePlot plot;
    plot.title = title;
    plot.x_label = "depth, mm";
    plot.y_label = "force, N";
    for (const Curve& c : curves) {
      if (c.figure != figure) continue;
      Series series{c.label, {}, c.forces, "", true};
      for (double depth : depths) series.x.push_back(1e3 * depth);
      plot.series.push_back(std::move(series));
    }
    write_svg(options.out / fmt::format("objects_push_{}.svg", figure), plot);
  }
  spdlog::info("objects-push: wrote objects_push.csv, objects_push.md and three figures in {}", options.out.string());
  return 0;
}

LabCommand add_objects_push_command(CLI::App& lab) {
  auto options = std::make_shared<ObjectsPushOptions>();
  CLI::App* command = lab.add_subcommand(
      "objects-push",
      "The several-objects paper's pushing test: the front box pushed 1-15 mm with its back free, fixed or on the "
      "elastic box behind it, and on B with three Young's moduli and Poisson ratios: objects_push.csv, "
      "objects_push.md, objects_push_{conditions,youngs,poisson}.svg in --out");
  command->add_option("--out", options->out, "Output directory")->required();
  return {command, [options] { return run_objects_push(*options); }};
}

}  // namespace cohaptic
