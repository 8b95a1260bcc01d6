#include "lab/hertz.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>

#include "common/mesh/read_gmsh.h"
#include "common/mesh/tet_mesh.h"
#include "common/model/compliance_setup.h"
#include "common/model/model.h"
#include "common/model/sphere_contact_reference.h"
#include "common/model/static_contact.h"
#include "common/scene/load_scene.h"
#include "common/study/svg_plot.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"
#include "common/util/stopwatch.h"

namespace cohaptic {
namespace {

constexpr double kQuarters = 4;        // the meshed quarter carries a quarter of the force
constexpr double kSidePerRadius = 20;  // the quarter block's side, in sphere radii

int core_cells(const HertzBlock& block) { return block.divisions / 2; }

double core_cell(const HertzBlock& block) { return block.core / core_cells(block); }  // over R

double change(double coarse, double fine) { return std::abs(fine - coarse) / std::abs(fine); }

// The quarter block's side [m]: 20 R for the box mesh; for a mesh file (millimetres), its
// side, checked to be the quarter block [0, s]^2 x [-s, 0] with s >= 20 R that the
// symmetry planes and the fixed bottom assume.
double quarter_block_side(const HertzBlock& block) {
  if (block.mesh.empty()) return kSidePerRadius * block.radius;
  const TetMesh mesh = read_gmsh(block.mesh).mesh;
  const Eigen::Vector3d min = mesh.nodes.rowwise().minCoeff() * 1e-3,
                        max = mesh.nodes.rowwise().maxCoeff() * 1e-3;
  const double side = max.x();
  const Eigen::Vector3d low(0, 0, -side), high(side, side, 0);
  if ((min - low).norm() > 1e-6 * side || (max - high).norm() > 1e-6 * side ||
      side < kSidePerRadius * block.radius)
    throw Error(fmt::format(
        "hertz: mesh {} spans ({:g}, {:g}, {:g}) to ({:g}, {:g}, {:g}) mm; a quarter block is "
        "(0, 0, -s) to (s, s, 0) with s at least {:g} mm (20 R)",
        block.mesh.string(), 1e3 * min.x(), 1e3 * min.y(), 1e3 * min.z(), 1e3 * max.x(),
        1e3 * max.y(), 1e3 * max.z(), 1e3 * kSidePerRadius * block.radius));
  return side;
}

// The mean edge of the tetrahedra with a node within 0.3 R of the contact point, over R.
double mean_edge_near_contact(const TetMesh& mesh, double radius) {
  constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  double sum = 0;
  long count = 0;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const Tet& tet = mesh.tets[static_cast<std::size_t>(t)];
    bool near = false;
    for (int k = 0; k < 4; ++k) near = near || mesh.nodes.col(tet[k]).norm() < 0.3 * radius;
    if (!near) continue;
    for (const auto& edge : kEdges)
      sum += (mesh.nodes.col(tet[edge[0]]) - mesh.nodes.col(tet[edge[1]])).norm();
    count += 6;
  }
  if (count == 0)
    throw Error("hertz: the mesh has no tetrahedron within 0.3 R of the contact point (0, 0, 0)");
  return sum / static_cast<double>(count) / radius;
}

}  // namespace

double hertz_cell_growth(const HertzBlock& block) {
  if (block.divisions < 2 || !(block.core > 0 && block.core < kSidePerRadius / 2))
    throw Error(fmt::format(
        "hertz: {} divisions, core {} R: need at least 2 divisions and a core from 0 to {} R",
        block.divisions, block.core, kSidePerRadius / 2));
  // The grown cells (the first r times a core cell) fill the rest of the side: bisection on
  // r, their length rising with it.
  const int grown = block.divisions - core_cells(block);
  const double rest = (kSidePerRadius - block.core) / core_cell(block);
  const auto length = [grown](double r) { return r * (std::pow(r, grown) - 1) / (r - 1); };
  double low = 1 + 1e-12, high = 2;
  while (length(high) < rest) high *= 2;
  for (int i = 0; i < 200 && high - low > 1e-15 * high; ++i)
    (length(0.5 * (low + high)) < rest ? low : high) = 0.5 * (low + high);
  return 0.5 * (low + high);
}

std::string hertz_block_yaml(const HertzBlock& block) {
  if (!(block.radius > 0))
    throw Error(fmt::format("hertz: radius {} m: need a positive radius", block.radius));
  const double r_mm = block.radius * 1e3, side = quarter_block_side(block) * 1e3;
  std::string mesh;
  if (block.mesh.empty()) {
    const double ratio = hertz_cell_growth(block);
    mesh = fmt::format(
        "box: {{min: [0, 0, {}], size: [{}, {}, {}], divisions: [{n}, {n}, {n}], grading: [{r}, "
        "{r}, {inv_r}], "
        "uniform_cells: [{c}, {c}, {c}]}}",
        -side, side, side, side, fmt::arg("n", block.divisions), fmt::arg("c", core_cells(block)),
        fmt::arg("r", fmt::format("{:.17g}", ratio)),
        fmt::arg("inv_r", fmt::format("{:.17g}", 1 / ratio)));
  } else {
    mesh = fmt::format("file: \"{}\"", std::filesystem::absolute(block.mesh).generic_string());
  }
  return fmt::format(
      R"(name: hertz
units: mm
objects:
  - name: block
    mesh:
      {mesh}
    material: {{model: linear_elastic, youngs_modulus: {e}, poisson_ratio: {nu}, element: {element}}}
    fixed:
      - plane: {{point: [0, 0, {neg_side}], normal: [0, 0, 1]}}
      - plane: {{point: [0, 0, 0], normal: [1, 0, 0]}}
        axes: x
      - plane: {{point: [0, 0, 0], normal: [0, 1, 0]}}
        axes: y
    touchable:
      - plane: {{point: [0, 0, 0], normal: [0, 0, 1]}}
    compliance: {{precompute: on_demand, disk_cache: false}}
tools:
  - {{name: A, shape: sphere, radius: {radius}}}
haptic: {{contact_model: sphere}}
)",
      fmt::arg("mesh", mesh), fmt::arg("neg_side", -side),
      fmt::arg("e", fmt::format("{:.17g}", block.material.youngs_modulus)),
      fmt::arg("nu", fmt::format("{:.17g}", block.material.poisson_ratio)),
      fmt::arg("element", formulation_name(block.material.formulation)),
      fmt::arg("radius", fmt::format("{:.17g}", r_mm)));
}

GmshScript hertz_quarter_block_script(const std::filesystem::path& geo, double fine) {
  return {geo, {{"fine", fine}, {"growth", kHertzGmshGrowth}}};
}

double hertz_force(const LinearElasticMaterial& material, double radius, double depth) {
  const double nu = material.poisson_ratio;
  return 4.0 / 3.0 * material.youngs_modulus / (1 - nu * nu) * std::sqrt(radius) *
         std::pow(depth, 1.5);
}

HertzMesh measure_hertz(const HertzBlock& given, const std::vector<double>& depth_ratios) {
  for (double ratio : depth_ratios)
    if (!(ratio > 0 && ratio <= 0.5))
      throw Error(fmt::format("hertz: depth ratio d/R = {} is not in (0, 0.5]", ratio));
  HertzBlock block = given;
  if (block.mesh.empty() && block.gmsh)
    block.mesh = mesh_with_gmsh(*block.gmsh, default_cache_directory() / "meshes");
  const Model model = build_model(parse_scene(hertz_block_yaml(block), "hertz.yaml"));
  const ElasticBody& body = single_elastic_body(model);
  HertzMesh mesh;
  mesh.name = block.mesh.empty() ? fmt::format("{} cells", block.divisions)
              : given.gmsh
                  ? fmt::format("gmsh, {:g} R at the contact", given.gmsh->parameters.at("fine"))
                  : block.mesh.filename().string();
  mesh.side = quarter_block_side(block) / block.radius;
  mesh.nodes = body.mesh.node_count();
  mesh.tets = body.mesh.tet_count();
  mesh.contact_cell =
      block.mesh.empty() ? core_cell(block) : mean_edge_near_contact(body.mesh, block.radius);
  SphereContactReference sphere_model(body);
  for (double depth_ratio : depth_ratios) {
    const std::vector<PressedTool> tool = {
        {Eigen::Vector3d(0, 0, block.radius * (1 - depth_ratio)), block.radius}};
    const SphereContactSolution solution = sphere_model.solve(tool);
    mesh.sphere_force.push_back(kQuarters * solution.reactions[0].z());
    mesh.contact_nodes.push_back(static_cast<int>(solution.contact_nodes().size()));
    const std::vector<ToolReaction> translation = contact_reactions_reference(
        body, find_tool_contacts(body, tool), {}, ContactModel::node_translation);
    mesh.translation_force.push_back(kQuarters * translation[0].reaction.z());
  }
  return mesh;
}

std::string hertz_table(const HertzOptions& options, const std::vector<HertzMesh>& meshes) {
  const HertzBlock& block = options.block;
  std::string out = fmt::format(
      "Sphere of R = {:g} mm into a block twice the quarter's side wide and one side deep, fixed "
      "at its bottom, E = {:g} "
      "Pa, nu = {:g}, {}.\nF / F_Hertz for the sphere model (full solve of the unilateral problem; "
      "in brackets the nodes "
      "it pushes in the quarter) and node translation:\n\n",
      block.radius * 1e3, block.material.youngs_modulus, block.material.poisson_ratio,
      formulation_name(block.material.formulation));
  out += "| mesh | quarter side / R | nodes | contact cell / R |";
  for (const char* model : {"sphere", "translation"})
    for (double d : options.depth_ratios) out += fmt::format(" {} d/R = {:g} |", model, d);
  out += "\n|---|---|---|---|";
  for (std::size_t i = 0; i < 2 * options.depth_ratios.size(); ++i) out += "---|";
  out += "\n";
  for (const HertzMesh& mesh : meshes) {
    out += fmt::format("| {} | {:g} | {} | {:.4f} |", mesh.name, mesh.side, mesh.nodes,
                       mesh.contact_cell);
    for (std::size_t j = 0; j < options.depth_ratios.size(); ++j)
      out += fmt::format(" {:.4f} ({}) |",
                         mesh.sphere_force[j] / hertz_force(block.material, block.radius,
                                                            options.depth_ratios[j] * block.radius),
                         mesh.contact_nodes[j]);
    for (std::size_t j = 0; j < options.depth_ratios.size(); ++j)
      out += fmt::format(" {:.4f} |", mesh.translation_force[j] /
                                          hertz_force(block.material, block.radius,
                                                      options.depth_ratios[j] * block.radius));
    out += "\n";
  }
  if (meshes.size() >= 2) {
    const HertzMesh& coarse = meshes[meshes.size() - 2];
    const HertzMesh& fine = meshes.back();
    out += fmt::format("| change {} → {} | | | |", coarse.name, fine.name);
    for (const auto member : {&HertzMesh::sphere_force, &HertzMesh::translation_force})
      for (std::size_t j = 0; j < options.depth_ratios.size(); ++j)
        out += fmt::format(" {:.1f} % |", 100 * change((coarse.*member)[j], (fine.*member)[j]));
    out += "\n";
  }
  out += "\nF_Hertz [N]:";
  for (double d : options.depth_ratios)
    out += fmt::format(" {:.5g} at d/R = {:g};",
                       hertz_force(block.material, block.radius, d * block.radius), d);
  out.back() = '\n';
  switch (options.meshes_from) {
    case HertzOptions::Meshes::gmsh:
      out += fmt::format(
          "Meshes: {} (a quarter block 40 R a side) meshed by gmsh, the element size at the "
          "contact as "
          "given in R and growing by {:g} per unit distance from it.\n",
          options.geo.string(), kHertzGmshGrowth);
      break;
    case HertzOptions::Meshes::boxes:
      out += fmt::format(
          "Meshes: box meshes of the quarter block 20 R a side, half the cells uniform in a core "
          "{:g} R "
          "a side at the contact, the others growing geometrically.\n",
          block.core);
      break;
    case HertzOptions::Meshes::files:
      out += "Meshes: the files named.\n";
      break;
  }
  return out;
}

int run_hertz(const HertzOptions& options) {
  std::vector<HertzBlock> blocks;
  switch (options.meshes_from) {
    case HertzOptions::Meshes::gmsh:
      if (!std::filesystem::exists(options.geo))
        throw Error(fmt::format(
            "hertz: no quarter block script at {} (run from the repository, or give --geo)",
            options.geo.string()));
      for (double fine : options.gmsh_fine) {
        blocks.push_back(options.block);
        blocks.back().gmsh = hertz_quarter_block_script(options.geo, fine);
      }
      break;
    case HertzOptions::Meshes::boxes:
      for (int divisions : options.divisions) {
        blocks.push_back(options.block);
        blocks.back().divisions = divisions;
      }
      break;
    case HertzOptions::Meshes::files:
      for (const std::filesystem::path& file : options.meshes) {
        blocks.push_back(options.block);
        blocks.back().mesh = file;
      }
      break;
  }
  std::vector<HertzMesh> meshes;
  for (const HertzBlock& block : blocks) {
    const Stopwatch watch;
    meshes.push_back(measure_hertz(block, options.depth_ratios));
    spdlog::info("{}: {} nodes, {} tetrahedra, {:.1f} s", meshes.back().name, meshes.back().nodes,
                 meshes.back().tets, watch.elapsed_ms() / 1000);
  }
  const std::string table = hertz_table(options, meshes);
  fmt::print("{}", table);
  if (options.out.empty()) return 0;
  std::filesystem::create_directories(options.out);
  AtomicFile markdown(options.out / "hertz.md");
  markdown.write(table);
  markdown.commit();
  LinePlot plot;
  plot.title = fmt::format("Sphere into a block against Hertz (nu = {:g}, {})",
                           options.block.material.poisson_ratio,
                           formulation_name(options.block.material.formulation));
  plot.x_label = "R / contact cell";
  plot.y_label = "F / F_Hertz, sphere model";
  // Node translation stays in the table: at a few percent of Hertz it would flatten the plot.
  for (std::size_t j = 0; j < options.depth_ratios.size(); ++j) {
    Series series{fmt::format("d/R = {:g}", options.depth_ratios[j]), {}, {}, {}, true};
    for (const HertzMesh& mesh : meshes) {
      series.x.push_back(1 / mesh.contact_cell);
      series.y.push_back(mesh.sphere_force[j] /
                         hertz_force(options.block.material, options.block.radius,
                                     options.depth_ratios[j] * options.block.radius));
    }
    plot.series.push_back(std::move(series));
  }
  const double first = 1 / meshes.front().contact_cell, last = 1 / meshes.back().contact_cell;
  for (const auto& [label, level] : {std::pair{"Hertz", 1.0}, std::pair{"Hertz + 5 %", 1.05}})
    plot.series.push_back(Series{label, {first, last}, {level, level}, "#888888", false});
  write_svg(options.out / "hertz.svg", plot);
  spdlog::info("wrote {}/hertz.md, hertz.svg", options.out.string());
  return 0;
}

LabCommand add_hertz_command(CLI::App& lab) {
  auto options = std::make_shared<HertzOptions>();
  CLI::App* command = lab.add_subcommand("hertz",
                                         "Press a sphere into a graded block and compare the force "
                                         "with Hertz's, mesh by mesh, for the sphere "
                                         "contact model and node translation; prints the table "
                                         "(and writes hertz.md, hertz.svg to --out). By "
                                         "default the blocks are scenes/hertz/quarter_block.geo "
                                         "meshed by gmsh at 0.05 R and 0.025 R under the "
                                         "contact (R = 10 mm: 0.5 and 0.25 mm)");
  command
      ->add_option("--poisson-ratio", options->block.material.poisson_ratio,
                   "The block's Poisson ratio")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.499));
  command->add_option("--element", options->block.material.formulation, "Element formulation")
      ->transform(CLI::CheckedTransformer(std::map<std::string, ElementFormulation>{
          {"linear_tet", ElementFormulation::linear_tet},
          {"nodal_pressure_tet", ElementFormulation::nodal_pressure_tet}}))
      ->capture_default_str();
  CLI::Option* gmsh_fine = command
                               ->add_option("--gmsh-fine", options->gmsh_fine,
                                            "Element size at the contact, in sphere radii, of each "
                                            "gmsh-graded quarter block (the default "
                                            "meshes)")
                               ->capture_default_str()
                               ->check(CLI::Range(0.005, 0.5));
  command->add_option("--geo", options->geo, "The quarter block's Gmsh script, for --gmsh-fine")
      ->capture_default_str();
  CLI::Option* divisions =
      command
          ->add_option("--divisions", options->divisions,
                       "Box meshes instead: cells per side of the quarter block")
          ->check(CLI::Range(2, 60));
  CLI::Option* meshes =
      command
          ->add_option(
              "--mesh", options->meshes,
              "Quarter-block mesh files instead (millimetres, R = 10 mm, [0, s]^2 x [-s, 0], e.g. "
              "scenes/hertz/quarter_block.geo meshed by gmsh)")
          ->check(CLI::ExistingFile);
  gmsh_fine->excludes(divisions)->excludes(meshes);
  divisions->excludes(meshes);
  command->add_option("--depths", options->depth_ratios, "Depths d/R")
      ->capture_default_str()
      ->check(CLI::Range(1e-4, 0.5));
  command
      ->add_option(
          "--core", options->block.core,
          "Side of the uniformly meshed core under the sphere, in sphere radii (half the cells)")
      ->capture_default_str()
      ->check(CLI::Range(0.05, 5.0));
  command->add_option("--out", options->out, "Also write hertz.md and hertz.svg here");
  return {command, [options, divisions, meshes] {
            if (*divisions) options->meshes_from = HertzOptions::Meshes::boxes;
            if (*meshes) options->meshes_from = HertzOptions::Meshes::files;
            return run_hertz(*options);
          }};
}

}  // namespace cohaptic
