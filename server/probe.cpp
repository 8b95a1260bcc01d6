#include "server/probe.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "common/mesh/write_gmsh.h"
#include "common/mesh/write_vtu.h"
#include "common/model/compliance_setup.h"
#include "common/model/static_contact.h"
#include "common/scene/load_scene.h"
#include "common/util/stopwatch.h"

namespace cohaptic {
namespace {

struct ProbeTimings {
  double load_ms = 0;        // scene, mesh, checks, surface
  double precompute_ms = 0;  // assembly, factorisation, compliance columns
  double solve_ms = 0;       // contacts and condensed forces
};

nlohmann::json vector_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json probe_json(const Model& model, const std::vector<PressedTool>& tools,
                          const std::vector<ToolReaction>& reactions, bool separately, const ProbeTimings& timings) {
  const double unit = model.scene.metres_per_unit;
  nlohmann::json out;
  out["scene"] = model.scene.file.string();
  out["units"] = model.scene.units;
  out["nodes"] = model.mesh.node_count();
  out["tets"] = model.mesh.tet_count();
  out["surface_triangles"] = model.surface.triangle_count();
  out["fixed_nodes"] = fixed_node_tags(model);
  out["touchable_nodes"] = model.touchable_nodes.size();
  out["material"] = {{"youngs_modulus_pa", model.scene.object.material.youngs_modulus},
                     {"poisson_ratio", model.scene.object.material.poisson_ratio}};
  out["tools_pressed"] = separately ? "separately" : "together";
  out["tools"] = nlohmann::json::array();
  for (std::size_t t = 0; t < tools.size(); ++t) {
    const ToolReaction& r = reactions[t];
    nlohmann::json tool;
    tool["position"] = vector_json(tools[t].position / unit);
    tool["signed_distance"] = r.query.signed_distance / unit;
    if (r.query.contact) {
      const ToolContact& c = *r.query.contact;
      const Triangle& tri = model.surface.triangles[c.triangle];
      nlohmann::json contact;
      contact["triangle"] = {model.mesh.node_tags[tri[0]], model.mesh.node_tags[tri[1]], model.mesh.node_tags[tri[2]]};
      contact["foot"] = vector_json(c.foot / unit);
      contact["weights"] = vector_json(c.weights);
      contact["depth"] = c.depth / unit;
      contact["displacement"] = {vector_json(c.displacement / unit), vector_json(c.displacement / unit),
                                 vector_json(c.displacement / unit)};
      contact["nodal_forces"] = {vector_json(r.nodal_forces.col(0)), vector_json(r.nodal_forces.col(1)),
                                 vector_json(r.nodal_forces.col(2))};
      tool["contact"] = contact;
    } else {
      tool["contact"] = nullptr;
    }
    tool["force"] = vector_json(r.reaction);
    out["tools"].push_back(tool);
  }
  out["timings_ms"] = {{"load", timings.load_ms}, {"precompute", timings.precompute_ms}, {"solve", timings.solve_ms}};
  return out;
}

std::string vec(const Eigen::Vector3d& v, int precision) {
  return fmt::format("({:.{}f}, {:.{}f}, {:.{}f})", v.x(), precision, v.y(), precision, v.z(), precision);
}

void print_table(const Model& model, const std::vector<PressedTool>& tools, const std::vector<ToolReaction>& reactions,
                 bool separately, const ProbeTimings& timings, const std::string& compliance_note) {
  const double unit = model.scene.metres_per_unit;
  const std::string& u = model.scene.units;
  const LinearElasticMaterial& material = model.scene.object.material;
  fmt::print("scene     {} ({})\n", model.scene.name, model.scene.file.string());
  fmt::print("mesh      {} nodes, {} tetrahedra, {} surface triangles; {} fixed nodes; {} touchable nodes\n",
             model.mesh.node_count(), model.mesh.tet_count(), model.surface.triangle_count(),
             fixed_node_tags(model).size(), model.touchable_nodes.size());
  fmt::print("material  E = {:g} Pa, nu = {:g}; contact model: node translation; tools pressed {}\n\n",
             material.youngs_modulus, material.poisson_ratio, separately ? "one at a time" : "together");
  fmt::print("{:<4} {:<28} {:>10} {:<20} {:<28} {:<30} {:>9}\n", "tool", fmt::format("position ({})", u),
             fmt::format("depth ({})", u), "triangle (node ids)", fmt::format("node displacement ({})", u),
             "reaction force on tool (N)", "|F| (N)");
  for (std::size_t t = 0; t < tools.size(); ++t) {
    const ToolReaction& r = reactions[t];
    if (!r.query.contact) {
      fmt::print("{:<4} {:<28} {:>10} no contact ({} {:.3f} {} from the surface)\n", t + 1, vec(tools[t].position / unit, 3),
                 "-", r.query.signed_distance < 0 ? "inside, but no touchable triangle;" : "outside,",
                 std::abs(r.query.signed_distance) / unit, u);
      continue;
    }
    const ToolContact& c = *r.query.contact;
    const Triangle& tri = model.surface.triangles[c.triangle];
    fmt::print("{:<4} {:<28} {:>10.3f} {:<20} {:<28} {:<30} {:>9.4f}\n", t + 1, vec(tools[t].position / unit, 3),
               c.depth / unit,
               fmt::format("{} {} {}", model.mesh.node_tags[tri[0]], model.mesh.node_tags[tri[1]], model.mesh.node_tags[tri[2]]),
               vec(c.displacement / unit, 3), vec(r.reaction, 4), r.reaction.norm());
  }
  fmt::print("\ntimings (ms): load {:.1f}, precompute {:.1f} (assemble {:.1f}, factor {:.1f}, compliance {:.1f}), solve {:.3f}\n",
             timings.load_ms, timings.precompute_ms, model.timings.assemble_ms, model.timings.factor_ms,
             timings.precompute_ms - model.timings.assemble_ms - model.timings.factor_ms, timings.solve_ms);
  if (!compliance_note.empty()) fmt::print("compliance cache: {}\n", compliance_note);
}

}  // namespace

int run_probe(const ProbeOptions& options) {
  ProbeTimings timings;
  Stopwatch watch;
  const Scene scene = load_scene(options.scene);
  const Model model = build_model(scene);
  const double elapsed_build = watch.lap_ms();
  timings.load_ms = elapsed_build - model.timings.assemble_ms - model.timings.factor_ms;
  timings.precompute_ms = model.timings.assemble_ms + model.timings.factor_ms;

  ComplianceColumns columns(*model.free_factor, model.dofs, compliance_row_nodes(model));
  const ComplianceSetup setup = prepare_compliance(model, columns, options.cache_directory);
  timings.precompute_ms += watch.lap_ms();

  std::vector<PressedTool> tools;
  for (std::size_t t = 0; t < options.tools.size(); ++t) {
    const ToolSpec& spec = scene.tools[std::min(t, scene.tools.size() - 1)];
    tools.push_back({options.tools[t] * scene.metres_per_unit, spec.radius});
  }
  std::vector<ToolReaction> reactions;
  if (options.separately) {
    for (const PressedTool& tool : tools)
      reactions.push_back(contact_reactions_condensed(model, columns, find_tool_contacts(model, {tool})).front());
  } else {
    reactions = contact_reactions_condensed(model, columns, find_tool_contacts(model, tools));
  }
  timings.solve_ms = watch.lap_ms();

  if (!options.export_vtu.empty() || !options.export_msh.empty()) {
    TetMesh in_scene_units = model.mesh;
    in_scene_units.nodes /= scene.metres_per_unit;
    if (!options.export_msh.empty()) {
      write_gmsh41(options.export_msh, in_scene_units);
      spdlog::info("wrote {}", options.export_msh.string());
    }
    if (!options.export_vtu.empty()) {
      if (options.separately && tools.size() > 1)
        spdlog::warn("--export-vtu with --separately: the field shows all tools' forces superposed");
      const Eigen::VectorXd u = displacement_under_reactions(model, reactions) / scene.metres_per_unit;
      write_vtu(options.export_vtu, in_scene_units,
                {{"displacement", Eigen::Map<const Eigen::Matrix3Xd>(u.data(), 3, model.mesh.node_count())}});
      spdlog::info("wrote {} (displacement in {})", options.export_vtu.string(), scene.units);
    }
  }

  if (options.json)
    fmt::print("{}\n", probe_json(model, tools, reactions, options.separately, timings).dump());
  else
    print_table(model, tools, reactions, options.separately, timings, setup.note);
  return 0;
}

}  // namespace cohaptic
