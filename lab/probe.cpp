#include "lab/probe.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <limits>
#include <memory>

#include "common/mesh/write_gmsh.h"
#include "common/mesh/write_vtu.h"
#include "common/contact/obstacle_constraints.h"
#include "common/model/compliance_setup.h"
#include "common/model/model.h"
#include "common/model/sphere_contact_reference.h"
#include "common/model/static_contact.h"
#include "common/scene/load_scene.h"
#include "common/sim/ir_build_options.h"
#include "common/sim/simulation.h"
#include "common/util/stopwatch.h"

namespace cohaptic {
namespace {

struct ProbeTimings {
  double load_ms = 0;        // scene, mesh, checks, surface
  double precompute_ms = 0;  // assembly, factorisation, compliance columns
  double ir_build_ms = 0;    // active sets and M~ (IR path)
  double solve_ms = 0;       // force evaluation, or the full sparse solve with --reference
};

// One probed tool: its contact (from the full-surface search) and the answer.
struct ProbedTool {
  PressedTool tool;
  ContactQuery query;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  // reaction on the tool [N]
  std::size_t ir_bytes = 0;
  int boundary_nodes = 0;
  int steps = 0;  // simulation steps taken (approach and settling)
  double condition_estimate = 0;
};

// At most this many steps at the final positions after an approach, for the sets to settle.
constexpr int kMaxSettlingSteps = 50;

// Parses "x,y,z" (three finite numbers separated by commas).
std::string parse_point(const std::string& text, Eigen::Vector3d& point) {
  double v[3];
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3 ||
      !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
    return "expected x,y,z (three numbers separated by commas), got '" + text + "'";
  point = {v[0], v[1], v[2]};
  return {};
}

// What the command line gives, before it becomes ProbeOptions.
struct ProbeCommandLine {
  ProbeOptions options;
  std::vector<std::string> tools;
  std::string contact_model;
  std::string precision = "f64";
  std::string cache_dir = default_cache_directory().string();
  bool no_disk_cache = false;
};

// Whether the probe needs no simulation: the sphere model's full solve with nothing held
// (no step-delay nodes) takes the obstacles' constraints itself, so --reference then
// needs neither the simulation nor its compliance columns.
bool reference_alone(const ProbeOptions& options, ContactModel contact_model) {
  return options.reference && contact_model == ContactModel::sphere && options.boundary_nodes == 0;
}

// Presses `tools` at once (every other scene tool absent) and fills in their answers;
// `columns` is null when reference_alone().
void press(const Model& model, ComplianceColumns* columns, const ProbeOptions& options,
           ContactModel contact_model, std::vector<ProbedTool>& tools,
           const std::vector<int>& users, ProbeTimings& timings) {
  const ElasticBody& body = single_elastic_body(model);
  std::vector<PressedTool> pressed;
  for (int u : users) pressed.push_back(tools[u].tool);
  const std::vector<ContactQuery> contacts = find_tool_contacts(body, pressed);
  for (std::size_t i = 0; i < users.size(); ++i) tools[users[i]].query = contacts[i];

  Stopwatch watch;
  std::unique_ptr<Simulation> simulation;
  HeldNodes held;
  if (columns) {
    SimulationOptions sim_options;
    sim_options.ir = ir_build_options(model.scene.haptic);
    sim_options.ir.patch_rings = options.patch_rings.value_or(model.scene.haptic.patch_rings);
    sim_options.ir.precision = options.precision;
    sim_options.ir.contact_model = contact_model;
    sim_options.ir.force_limit =
        std::numeric_limits<double>::infinity();  // the probe reports physics
    sim_options.step_delay_nodes = options.boundary_nodes;
    simulation = std::make_unique<Simulation>(body, model.obstacles, *columns, model.scene.tools,
                                              sim_options);
    // Each tool goes in a straight line from where its contact point touches the rest
    // surface (its position less the contact's displacement) to its position.
    StepReport report;
    int steps = 0;
    for (int k = 1; k <= options.approach_steps; ++k, ++steps) {
      const double fraction = static_cast<double>(k) / options.approach_steps;
      for (std::size_t i = 0; i < users.size(); ++i) {
        const Eigen::Vector3d& position = pressed[i].position;
        const Eigen::Vector3d travel =
            contacts[i].contact ? contacts[i].contact->displacement : Eigen::Vector3d::Zero();
        simulation->set_tool(users[i], position - (1 - fraction) * travel);
      }
      report = simulation->step(steps * 1e-3);
    }
    if (options.approach_steps > 1)
      for (int settling = 0; report.rebuilt && settling < kMaxSettlingSteps; ++settling, ++steps)
        report = simulation->step(steps * 1e-3);
    if (report.rebuilt && options.approach_steps > 1)
      spdlog::warn("probe: the sets still changed after {} steps at the final positions",
                   kMaxSettlingSteps);
    timings.ir_build_ms += watch.lap_ms();
    for (int u : users) {
      tools[u].boundary_nodes = report.boundary_nodes;
      tools[u].steps = steps;
      if (const auto ir = simulation->ir(u)) {
        tools[u].ir_bytes = ir->ir.size_bytes();
        tools[u].condition_estimate = ir->condition_estimate;
      }
    }
    held = {simulation->condensation().boundary_nodes(), simulation->boundary_displacement()};
  }
  if (options.reference) {
    std::vector<Eigen::Vector3d> reactions;
    if (contact_model == ContactModel::sphere) {
      reactions = SphereContactReference(body, obstacle_constraints(body.mesh, body.surface,
                                                                    body.dofs, model.obstacles))
                      .solve(pressed, held)
                      .reactions;
    } else {
      for (const ToolReaction& reaction :
           contact_reactions_reference(body, contacts, held, contact_model))
        reactions.push_back(reaction.reaction);
    }
    for (std::size_t i = 0; i < users.size(); ++i) tools[users[i]].force = reactions[i];
  } else {
    for (int u : users) tools[u].force = simulation->force(u).force;
  }
  timings.solve_ms += watch.lap_ms();
}

nlohmann::json vector_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json probe_json(const Model& model, const ProbeOptions& options,
                          ContactModel contact_model, const std::vector<ProbedTool>& tools,
                          const ProbeTimings& timings) {
  const ElasticBody& body = single_elastic_body(model);
  const double unit = model.scene.metres_per_unit;
  nlohmann::json out;
  out["scene"] = model.scene.file.string();
  out["units"] = model.scene.units;
  out["nodes"] = body.mesh.node_count();
  out["tets"] = body.mesh.tet_count();
  out["surface_triangles"] = body.surface.triangle_count();
  out["fixed_nodes"] = fixed_node_tags(body);
  out["touchable_nodes"] = body.touchable_nodes.size();
  out["material"] = {{"youngs_modulus_pa", body.spec.material.youngs_modulus},
                     {"poisson_ratio", body.spec.material.poisson_ratio},
                     {"element", formulation_name(body.spec.material.formulation)}};
  out["method"] = options.reference ? "reference" : "ir";
  out["contact_model"] = contact_model_name(contact_model);
  out["ir_precision"] = options.precision == IrPrecision::f32 ? "f32" : "f64";
  out["patch_rings"] = options.patch_rings.value_or(model.scene.haptic.patch_rings);
  out["tools_pressed"] = options.separately ? "separately" : "together";
  out["tools"] = nlohmann::json::array();
  for (const ProbedTool& probed : tools) {
    nlohmann::json tool;
    tool["position"] = vector_json(probed.tool.position / unit);
    tool["signed_distance"] = probed.query.signed_distance / unit;
    if (probed.query.contact) {
      const ToolContact& c = *probed.query.contact;
      const Triangle& tri = body.surface.triangles[c.triangle];
      nlohmann::json contact;
      contact["triangle"] = {body.mesh.node_tags[tri[0]], body.mesh.node_tags[tri[1]],
                             body.mesh.node_tags[tri[2]]};
      contact["foot"] = vector_json(c.foot / unit);
      contact["weights"] = vector_json(c.weights);
      contact["depth"] = c.depth / unit;
      contact["displacement"] = {vector_json(c.displacement / unit),
                                 vector_json(c.displacement / unit),
                                 vector_json(c.displacement / unit)};
      tool["contact"] = contact;
    } else {
      tool["contact"] = nullptr;
    }
    tool["force"] = vector_json(probed.force);
    tool["ir"] = {{"bytes", probed.ir_bytes},
                  {"boundary_nodes", probed.boundary_nodes},
                  {"steps", probed.steps},
                  {"condition_estimate", probed.condition_estimate}};
    out["tools"].push_back(tool);
  }
  out["timings_ms"] = {{"load", timings.load_ms},
                       {"precompute", timings.precompute_ms},
                       {"ir_build", timings.ir_build_ms},
                       {"solve", timings.solve_ms}};
  return out;
}

std::string vec(const Eigen::Vector3d& v, int precision) {
  return fmt::format("({:.{}f}, {:.{}f}, {:.{}f})", v.x(), precision, v.y(), precision, v.z(),
                     precision);
}

void print_table(const Model& model, const ProbeOptions& options, ContactModel contact_model,
                 const std::vector<ProbedTool>& tools, const ProbeTimings& timings,
                 const std::string& compliance_note) {
  const ElasticBody& body = single_elastic_body(model);
  const double unit = model.scene.metres_per_unit;
  const std::string& u = model.scene.units;
  const LinearElasticMaterial& material = body.spec.material;
  fmt::print("scene     {} ({})\n", model.scene.name, model.scene.file.string());
  fmt::print(
      "mesh      {} nodes, {} tetrahedra, {} surface triangles; {} fixed nodes; {} touchable "
      "nodes\n",
      body.mesh.node_count(), body.mesh.tet_count(), body.surface.triangle_count(),
      fixed_node_tags(body).size(), body.touchable_nodes.size());
  fmt::print("material  E = {:g} Pa, nu = {:g}, {}\n", material.youngs_modulus,
             material.poisson_ratio, formulation_name(material.formulation));
  fmt::print(
      "method    {}; contact model {}; tools pressed {}; {} boundary nodes held after {} step{}\n",
      options.reference ? "full sparse solve (--reference)"
                        : fmt::format("IR ({}, patch rings {})",
                                      options.precision == IrPrecision::f32 ? "f32" : "f64",
                                      options.patch_rings.value_or(model.scene.haptic.patch_rings)),
      contact_model_name(contact_model), options.separately ? "one at a time" : "together",
      tools.empty() ? 0 : tools.front().boundary_nodes, tools.empty() ? 0 : tools.front().steps,
      !tools.empty() && tools.front().steps == 1 ? "" : "s");
  fmt::print("\n{:<4} {:<28} {:>10} {:<20} {:<28} {:<30} {:>9} {:>9}\n", "tool",
             fmt::format("position ({})", u), fmt::format("depth ({})", u), "triangle (node ids)",
             fmt::format("node displacement ({})", u), "reaction force on tool (N)", "|F| (N)",
             "IR bytes");
  const double limit = model.scene.haptic.force_limit_n;
  bool over_limit = false;
  for (std::size_t t = 0; t < tools.size(); ++t) {
    const ProbedTool& probed = tools[t];
    if (!probed.query.contact) {
      fmt::print(
          "{:<4} {:<28} {:>10} no contact ({} {:.3f} {} from the surface)\n", t + 1,
          vec(probed.tool.position / unit, 3), "-",
          probed.query.signed_distance < 0 ? "inside, but no touchable triangle;" : "outside,",
          std::abs(probed.query.signed_distance) / unit, u);
      continue;
    }
    const ToolContact& c = *probed.query.contact;
    const Triangle& tri = body.surface.triangles[c.triangle];
    const bool over = probed.force.norm() > limit;
    over_limit |= over;
    fmt::print("{:<4} {:<28} {:>10.3f} {:<20} {:<28} {:<30} {:>8.4f}{} {:>9}\n", t + 1,
               vec(probed.tool.position / unit, 3), c.depth / unit,
               fmt::format("{} {} {}", body.mesh.node_tags[tri[0]], body.mesh.node_tags[tri[1]],
                           body.mesh.node_tags[tri[2]]),
               vec(c.displacement / unit, 3), vec(probed.force, 4), probed.force.norm(),
               over ? "*" : " ", probed.ir_bytes);
  }
  if (over_limit)
    fmt::print(
        "* above the scene's haptic force limit of {:g} N (a haptic client would clamp it)\n",
        limit);
  fmt::print(
      "\ntimings (ms): load {:.1f}, precompute {:.1f} (assemble {:.1f}, compliance {:.1f}), "
      "IR build {:.3f}, {} {:.3f}; K_ff {}\n",
      timings.load_ms, timings.precompute_ms, body.timings.assemble_ms,
      timings.precompute_ms - body.timings.assemble_ms, timings.ir_build_ms,
      options.reference ? "full solve" : "force evaluation", timings.solve_ms,
      body.free_factor.factored()
          ? fmt::format("factored in {:.1f} (within the above)", body.free_factor.factor_ms())
          : std::string("not factored (not needed)"));
  if (!compliance_note.empty()) fmt::print("compliance cache: {}\n", compliance_note);
}

}  // namespace

int run_probe(const ProbeOptions& options) {
  ProbeTimings timings;
  Stopwatch watch;
  Scene scene = load_scene(options.scene);
  // One user per --tool; tool k takes the shape of the scene's k-th tool, or of its last.
  while (scene.tools.size() < options.tools.size()) {
    scene.tools.push_back(scene.tools.back());
    scene.tools.back().name += "'";
  }
  const ContactModel contact_model = options.contact_model.value_or(scene.haptic.contact_model);
  const Model model = build_model(scene);
  const ElasticBody& body = single_elastic_body(model);
  const double elapsed_build = watch.lap_ms();
  timings.load_ms = elapsed_build - body.timings.assemble_ms;
  timings.precompute_ms = body.timings.assemble_ms;

  std::unique_ptr<ComplianceColumns> columns;
  std::string compliance_note = "no compliance columns: the full solve alone";
  if (!reference_alone(options, contact_model)) {
    columns = std::make_unique<ComplianceColumns>(
        body.free_factor, body.dofs,
        compliance_row_nodes(body, options.boundary_nodes > 0 || !model.obstacles.empty()));
    compliance_note = prepare_compliance(body, *columns, options.cache_directory).note;
  }
  timings.precompute_ms += watch.lap_ms();

  std::vector<ProbedTool> tools;
  for (const Eigen::Vector3d& position : options.tools) {
    ProbedTool probed;
    probed.tool = {position * scene.metres_per_unit, scene.tools[tools.size()].radius};
    tools.push_back(probed);
  }
  if (options.separately) {
    for (int u = 0; u < static_cast<int>(tools.size()); ++u)
      press(model, columns.get(), options, contact_model, tools, {u}, timings);
  } else {
    std::vector<int> all(tools.size());
    for (std::size_t u = 0; u < all.size(); ++u) all[u] = static_cast<int>(u);
    press(model, columns.get(), options, contact_model, tools, all, timings);
  }

  if (!options.export_vtu.empty() || !options.export_msh.empty()) {
    TetMesh in_scene_units = body.mesh;
    in_scene_units.nodes /= scene.metres_per_unit;
    if (!options.export_msh.empty()) {
      write_gmsh41(options.export_msh, in_scene_units);
      spdlog::info("wrote {}", options.export_msh.string());
    }
    if (!options.export_vtu.empty()) {
      if (options.separately && tools.size() > 1)
        spdlog::warn("--export-vtu with --separately: the field shows all tools pressing together");
      std::vector<PressedTool> pressed;
      for (const ProbedTool& probed : tools) pressed.push_back(probed.tool);
      Eigen::VectorXd u;
      if (contact_model == ContactModel::sphere)
        SphereContactReference(
            body, obstacle_constraints(body.mesh, body.surface, body.dofs, model.obstacles))
            .solve(pressed, {}, &u);
      else
        contact_reactions_reference(body, find_tool_contacts(body, pressed), {}, contact_model, &u);
      u /= scene.metres_per_unit;
      write_vtu(options.export_vtu, in_scene_units,
                {{"displacement",
                  Eigen::Map<const Eigen::Matrix3Xd>(u.data(), 3, body.mesh.node_count())}});
      spdlog::info("wrote {} (displacement in {}, without held boundary nodes)",
                   options.export_vtu.string(), scene.units);
    }
  }

  if (options.json)
    fmt::print("{}\n", probe_json(model, options, contact_model, tools, timings).dump());
  else
    print_table(model, options, contact_model, tools, timings, compliance_note);
  return 0;
}

LabCommand add_probe_command(CLI::App& lab) {
  auto line = std::make_shared<ProbeCommandLine>();
  ProbeOptions& probe = line->options;
  CLI::App* command = lab.add_subcommand("probe",
                                         "Static reaction force at tool positions pressed into the "
                                         "scene's object, through the intermediate "
                                         "representation (condensed M~) and the haptic force "
                                         "evaluator, or the full FEM solve. Prints a table, "
                                         "or JSON with --json.");
  command->add_option("--scene", probe.scene, "Scene file (YAML)")
      ->required()
      ->check(CLI::ExistingFile);
  command
      ->add_option(
          "--tool", line->tools,
          "Tool position x,y,z in the scene's units; repeat for several tools pressing at once. "
          "Tool k takes the shape of the scene's k-th tool (the last one if there are fewer)")
      ->required();
  command->add_flag("--separately", probe.separately,
                    "Press each tool alone (one solve per tool) instead of all tools at once");
  command
      ->add_option("--approach-steps", probe.approach_steps,
                   "Simulation steps that bring each tool from touching the rest surface to its "
                   "position; with "
                   "more than 1 the last position is stepped again until no set changes (under the "
                   "translation and "
                   "point models obstacles hold the nodes where they reach them, so a one-step "
                   "press from rest can "
                   "hold more)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  command
      ->add_option("--boundary-nodes", probe.boundary_nodes,
                   "Hold the N surface nodes nearest the tools at rest (the paper's step-delay "
                   "T150/T300 sets)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command
      ->add_option("--contact-model", line->contact_model,
                   "translation (the paper's: the triangle's nodes follow the tool), point (the "
                   "contact point "
                   "follows it with least energy) or sphere (the surface nodes a sphere tool "
                   "pushes are held on its "
                   "surface, frictionless and unilateral); default: the scene's")
      ->check(CLI::IsMember({"translation", "point", "sphere"}));
  command
      ->add_option("--ir-precision", line->precision,
                   "Storage of M~ and u_B in the IR: f64 or f32 (inversion is always double)")
      ->check(CLI::IsMember({"f64", "f32"}))
      ->capture_default_str();
  command
      ->add_option(
          "--patch-rings", probe.patch_rings,
          "Rings of neighbouring triangles in each IR's contact patch (0-4); default: the scene's")
      ->check(CLI::Range(0, 4));
  command->add_flag("--reference", probe.reference,
                    "Full sparse FEM solve instead of the condensed IR (slow; the answer the IR is "
                    "checked against)");
  command->add_flag("--json", probe.json, "Print one JSON object on stdout instead of the table");
  command->add_option("--export-vtu", probe.export_vtu,
                      "Write the mesh with the displacement field (.vtu, for ParaView)");
  command->add_option("--export-msh", probe.export_msh,
                      "Write the mesh as Gmsh 4.1 ASCII (its node ids are the ones reported)");
  command->add_option("--cache-dir", line->cache_dir, "Directory of the on-disk compliance cache")
      ->capture_default_str();
  command->add_flag("--no-disk-cache", line->no_disk_cache,
                    "Neither read nor write the on-disk compliance cache");

  return {command, [line] {
            ProbeOptions options = line->options;
            for (const std::string& text : line->tools) {
              Eigen::Vector3d point;
              if (const std::string problem = parse_point(text, point); !problem.empty()) {
                fmt::print(stderr, "cohaptic-lab probe: --tool: {}\n", problem);
                return 2;
              }
              options.tools.push_back(point);
            }
            if (!line->no_disk_cache) options.cache_directory = line->cache_dir;
            if (!line->contact_model.empty())
              options.contact_model =
                  line->contact_model == "translation" ? ContactModel::node_translation
                  : line->contact_model == "point"     ? ContactModel::point_constraint
                                                       : ContactModel::sphere;
            options.precision = line->precision == "f32" ? IrPrecision::f32 : IrPrecision::f64;
            return run_probe(options);
          }};
}

}  // namespace cohaptic
