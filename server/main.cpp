// cohaptic-server: the simulation server's command line. Subcommands:
//   probe  static reaction forces at tool positions on a scene (see README.md).
#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>

#include "common/model/compliance_setup.h"
#include "common/util/error.h"
#include "server/probe.h"

namespace {

// Parses "x,y,z" (three finite numbers separated by commas).
std::string parse_point(const std::string& text, Eigen::Vector3d& point) {
  double v[3];
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3 || !std::isfinite(v[0]) ||
      !std::isfinite(v[1]) || !std::isfinite(v[2]))
    return "expected x,y,z (three numbers separated by commas), got '" + text + "'";
  point = {v[0], v[1], v[2]};
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  auto logger = spdlog::stderr_color_mt("cohaptic");
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");

  CLI::App app{"cohaptic-server: FEM simulation server for networked haptic collaboration"};
  app.require_subcommand(1);
  app.fallthrough();  // --log-level may follow the subcommand
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "Log verbosity on stderr: trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();

  cohaptic::ProbeOptions probe;
  std::vector<std::string> tool_texts;
  std::string cache_dir = cohaptic::default_cache_directory().string();
  bool no_disk_cache = false;
  CLI::App* probe_cmd = app.add_subcommand(
      "probe",
      "Static reaction force at tool positions pressed into the scene's object, through the intermediate "
      "representation (condensed M~) and the haptic force evaluator, or the full FEM solve. Prints a table, "
      "or JSON with --json.");
  probe_cmd->add_option("--scene", probe.scene, "Scene file (YAML)")->required()->check(CLI::ExistingFile);
  probe_cmd
      ->add_option("--tool", tool_texts,
                   "Tool position x,y,z in the scene's units; repeat for several tools pressing at once. "
                   "Tool k takes the shape of the scene's k-th tool (the last one if there are fewer)")
      ->required();
  probe_cmd->add_flag("--separately", probe.separately,
                     "Press each tool alone (one solve per tool) instead of all tools at once");
  std::string contact_model, precision = "f64";
  probe_cmd->add_option("--boundary-nodes", probe.boundary_nodes,
                        "Hold the N surface nodes nearest the tools at rest (the paper's step-delay T150/T300 sets)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  probe_cmd->add_option("--contact-model", contact_model,
                        "translation (the paper's: the triangle's nodes follow the tool) or point (the contact point "
                        "follows it with least energy); default: the scene's")
      ->check(CLI::IsMember({"translation", "point"}));
  probe_cmd->add_option("--ir-precision", precision, "Storage of M~ and u_B in the IR: f64 or f32 (inversion is always double)")
      ->check(CLI::IsMember({"f64", "f32"}))
      ->capture_default_str();
  probe_cmd->add_option("--patch-rings", probe.patch_rings,
                        "Rings of neighbouring triangles in each IR's contact patch (0-4); default: the scene's")
      ->check(CLI::Range(0, 4));
  probe_cmd->add_flag("--reference", probe.reference,
                      "Full sparse FEM solve instead of the condensed IR (slow; the answer the IR is checked against)");
  probe_cmd->add_flag("--json", probe.json, "Print one JSON object on stdout instead of the table");
  probe_cmd->add_option("--export-vtu", probe.export_vtu, "Write the mesh with the displacement field (.vtu, for ParaView)");
  probe_cmd->add_option("--export-msh", probe.export_msh, "Write the mesh as Gmsh 4.1 ASCII (its node ids are the ones reported)");
  probe_cmd->add_option("--cache-dir", cache_dir, "Directory of the on-disk compliance cache")->capture_default_str();
  probe_cmd->add_flag("--no-disk-cache", no_disk_cache, "Neither read nor write the on-disk compliance cache");

  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(log_level));

  try {
    if (probe_cmd->parsed()) {
      for (const std::string& text : tool_texts) {
        Eigen::Vector3d point;
        if (const std::string problem = parse_point(text, point); !problem.empty()) {
          fmt::print(stderr, "cohaptic-server probe: --tool: {}\n", problem);
          return 2;
        }
        probe.tools.push_back(point);
      }
      if (!no_disk_cache) probe.cache_directory = cache_dir;
      if (!contact_model.empty())
        probe.contact_model =
            contact_model == "translation" ? cohaptic::ContactModel::node_translation : cohaptic::ContactModel::point_constraint;
      probe.precision = precision == "f32" ? cohaptic::IrPrecision::f32 : cohaptic::IrPrecision::f64;
      return cohaptic::run_probe(probe);
    }
  } catch (const cohaptic::Error& e) {
    spdlog::error("{}", e.what());
    return 1;
  } catch (const std::exception& e) {
    spdlog::error("unexpected failure: {}", e.what());
    return 1;
  }
  return 0;
}
