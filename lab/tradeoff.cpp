#include "lab/tradeoff.h"
#include "lab/tradeoff_tally.h"
#include "lab/tradeoff_wire_bytes.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "common/contact/obstacle_constraints.h"
#include "common/fem/compliance.h"
#include "common/ir/build_ir.h"
#include "common/ir/evaluate_force.h"
#include "common/model/compliance_setup.h"
#include "common/model/model.h"
#include "common/model/contact_reference.h"
#include "common/model/sphere_contact_reference.h"
#include "common/scene/load_scene.h"
#include "common/sim/ir_build_options.h"
#include "common/sim/simulation.h"
#include "common/study/svg_plot.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"
#include "common/util/stopwatch.h"
#include "lab/tradeoff_home_spring.h"
#include "lab/tradeoff_mass_spring.h"

namespace cohaptic {
namespace {

constexpr double kSimulationRateHz = 1000;

bool all_spheres(const Scene& scene) {
  return std::all_of(scene.tools.begin(), scene.tools.end(),
                     [](const ToolSpec& tool) { return tool.radius > 0; });
}

HeldNodes held_nodes(const Simulation& simulation) {
  return {simulation.condensation().boundary_nodes(), simulation.boundary_displacement()};
}

int samples_per(double sample_rate_hz, double rate_hz, const std::string& what) {
  const double ratio = sample_rate_hz / rate_hz;
  if (!(rate_hz > 0) || std::abs(ratio - std::round(ratio)) > 1e-9 || ratio < 1)
    throw Error(fmt::format("tradeoff: the {} ({:g} Hz) must divide {:g} Hz", what, rate_hz,
                            sample_rate_hz));
  return static_cast<int>(std::lround(ratio));
}

// The full sparse solve of a contact model on one mesh: the sphere model's unilateral
// problem with the obstacles' constraints (SphereContactReference), or node translation
// (ContactReference) for the paper's two models, which share it as their reference.
class FullSolve {
 public:
  FullSolve(const ElasticBody& body, ContactModel model, std::span<const Obstacle> obstacles) {
    if (model == ContactModel::sphere)
      sphere_ = std::make_unique<SphereContactReference>(
          body, obstacles.empty()
                    ? std::vector<SphereConstraint>{}
                    : obstacle_constraints(body.mesh, body.surface, body.dofs, obstacles));
    else
      translation_ = std::make_unique<ContactReference>(body);
  }

  std::vector<Eigen::Vector3d> forces(const std::vector<PressedTool>& tools,
                                      const HeldNodes& held = {}) {
    return sphere_ ? sphere_->solve(tools, held).reactions : translation_->forces(tools, held);
  }

  std::size_t factorisations() const {
    return sphere_ ? sphere_->factorisations() : translation_->factorisations();
  }

 private:
  std::unique_ptr<ContactReference> translation_;
  std::unique_ptr<SphereContactReference> sphere_;
};

double model_memory_mb(const ElasticBody& body, const ComplianceColumns& columns) {
  const double stiffness =
      static_cast<double>(body.stiffness.nonZeros()) * (sizeof(double) + sizeof(int));
  const double factor = body.free_factor->factor_nonzeros() * (sizeof(double) + sizeof(int));
  const double compliance =
      static_cast<double>(columns.column_count() * columns.row_nodes().size()) * 9 * sizeof(double);
  return (stiffness + factor + compliance) / 1e6;
}

}  // namespace

std::vector<TradeoffSetting> tradeoff_grid(const Scene& scene, const std::vector<int>& divisions,
                                           double sample_rate_hz) {
  TradeoffSetting base;
  base.formulation = single_elastic_object(scene).material.formulation;
  base.contact_model = scene.haptic.contact_model;
  base.patch_rings = scene.haptic.patch_rings;
  base.haptic_rate_hz = scene.haptic.rate_hz;
  base.boundary_truncation = scene.haptic.boundary_truncation;
  std::vector<TradeoffSetting> grid = {base};
  const auto vary = [&](const std::string& knob, const std::string& value, auto&& change) {
    TradeoffSetting setting = base;
    setting.knob = knob;
    setting.value = value;
    change(setting);
    grid.push_back(setting);
  };
  if (single_elastic_object(scene).mesh.box) {
    const int own = single_elastic_object(scene).mesh.box->divisions.maxCoeff();
    for (int d : divisions)
      if (d != own)
        vary("divisions", std::to_string(d), [d](TradeoffSetting& s) { s.divisions = d; });
  }
  const ElementFormulation other_element = base.formulation == ElementFormulation::linear_tet
                                               ? ElementFormulation::nodal_pressure_tet
                                               : ElementFormulation::linear_tet;
  vary("element", formulation_name(other_element),
       [&](TradeoffSetting& s) { s.formulation = other_element; });
  for (ContactModel other :
       {ContactModel::sphere, ContactModel::node_translation, ContactModel::point_constraint})
    if (other != base.contact_model && (other != ContactModel::sphere || all_spheres(scene)))
      vary("contact_model", contact_model_name(other),
           [other](TradeoffSetting& s) { s.contact_model = other; });
  for (int rings : {0, 2})
    if (rings != base.patch_rings)
      vary("patch_rings", std::to_string(rings),
           [rings](TradeoffSetting& s) { s.patch_rings = rings; });
  vary("precision", "f32", [](TradeoffSetting& s) { s.precision = IrPrecision::f32; });
  if (!scene.obstacles.empty())
    for (double threshold : {0.01, 0.05, 0.2})
      vary("boundary_truncation", fmt::format("{:g}", threshold),
           [threshold](TradeoffSetting& s) { s.boundary_truncation = threshold; });
  for (double rate : {20.0, 5.0})
    vary("ir_rate_hz", fmt::format("{:g}", rate),
         [rate](TradeoffSetting& s) { s.ir_rate_hz = rate; });
  for (double rate : {500.0, 1000.0, 2000.0, 5000.0})
    if (rate != base.haptic_rate_hz && std::fmod(sample_rate_hz, rate) == 0)
      vary("haptic_rate_hz", fmt::format("{:g}", rate),
           [rate](TradeoffSetting& s) { s.haptic_rate_hz = rate; });
  return grid;
}

std::vector<TradeoffSetting> only_knobs(const std::vector<TradeoffSetting>& grid,
                                        const std::vector<std::string>& knobs) {
  if (knobs.empty()) return grid;
  for (const std::string& knob : knobs)
    if (std::none_of(grid.begin(), grid.end(),
                     [&](const TradeoffSetting& s) { return s.knob == knob; }))
      throw Error(fmt::format("--knob {}: this scene's grid has no setting of that knob", knob));
  std::vector<TradeoffSetting> only;
  for (const TradeoffSetting& setting : grid)
    if (setting.knob == "baseline" ||
        std::find(knobs.begin(), knobs.end(), setting.knob) != knobs.end())
      only.push_back(setting);
  return only;
}

Scene scene_with(const Scene& scene, const TradeoffSetting& setting) {
  Scene out = scene;
  ElasticObjectSpec& object = single_elastic_object(out);
  if (setting.divisions > 0) {
    if (!object.mesh.box)
      throw Error(
          fmt::format("{}: mesh divisions can only be varied for a box mesh", scene.file.string()));
    BoxMeshSpec& box = *object.mesh.box;
    const double longest = box.size.maxCoeff();
    for (int axis = 0; axis < 3; ++axis)
      box.divisions[axis] =
          std::max(1, static_cast<int>(std::lround(setting.divisions * box.size[axis] / longest)));
  }
  object.material.formulation = setting.formulation;
  object.compliance.disk_cache = false;
  out.haptic.contact_model = setting.contact_model;
  out.haptic.patch_rings = setting.patch_rings;
  out.haptic.rate_hz = setting.haptic_rate_hz;
  out.haptic.boundary_truncation = setting.boundary_truncation;
  return out;
}

ReferenceTrace reference_trace(const Scene& reference, const std::vector<Trajectory>& motions,
                               double sample_rate_hz) {
  if (motions.size() != reference.tools.size())
    throw Error(
        fmt::format("tradeoff: {} motions for the scene's {} tools (give one --motion per tool)",
                    motions.size(), reference.tools.size()));
  const Stopwatch watch;
  const Model model = build_model(reference);
  const ElasticBody& body = single_elastic_body(model);
  FullSolve solver(body, reference.haptic.contact_model, model.obstacles);
  // With obstacles under the translation and point models, which nodes rest on them at each
  // moment comes from the simulation's active set on this mesh; the forces then from the
  // full solve with those nodes held. The sphere model's full solve holds them itself.
  std::unique_ptr<ComplianceColumns> columns;
  std::unique_ptr<Simulation> active_set;
  if (!reference.obstacles.empty() && reference.haptic.contact_model != ContactModel::sphere) {
    columns = std::make_unique<ComplianceColumns>(body.free_factor, body.dofs,
                                                  compliance_row_nodes(body, true));
    prepare_compliance(body, *columns, std::nullopt);
    SimulationOptions options;
    options.ir = ir_build_options(reference.haptic);
    options.ir.force_limit = std::numeric_limits<double>::infinity();
    active_set =
        std::make_unique<Simulation>(body, model.obstacles, *columns, reference.tools, options);
  }
  ReferenceTrace trace;
  trace.sample_rate_hz = sample_rate_hz;
  trace.nodes = body.mesh.node_count();
  trace.tets = body.mesh.tet_count();
  double duration = 0;
  for (const Trajectory& motion : motions) duration = std::max(duration, motion.duration());
  const auto samples = static_cast<std::size_t>(std::floor(duration * sample_rate_hz)) + 1;
  std::vector<PressedTool> tools(motions.size());
  Stopwatch progress;
  for (std::size_t j = 0; j < samples; ++j) {
    const double t = static_cast<double>(j) / sample_rate_hz;
    if (progress.elapsed_ms() > 10000) {
      spdlog::info("reference: {:.0f} % ({} of {} samples, {} factorisations)",
                   100.0 * static_cast<double>(j) / static_cast<double>(samples), j, samples,
                   solver.factorisations());
      progress.lap_ms();
    }
    for (std::size_t u = 0; u < motions.size(); ++u)
      tools[u] = {motions[u].position(t), reference.tools[u].radius};
    std::vector<Eigen::Vector3d> positions;
    for (const PressedTool& tool : tools) positions.push_back(tool.position);
    trace.positions.push_back(std::move(positions));
    if (active_set) {
      for (std::size_t u = 0; u < tools.size(); ++u)
        active_set->set_tool(static_cast<int>(u), tools[u].position);
      active_set->step(t);
      trace.forces.push_back(solver.forces(tools, held_nodes(*active_set)));
    } else {
      trace.forces.push_back(solver.forces(tools));
    }
    for (const Eigen::Vector3d& f : trace.forces.back())
      trace.peak_force = std::max(trace.peak_force, f.norm());
  }
  trace.factorisations = solver.factorisations();
  trace.seconds = watch.elapsed_ms() / 1000;
  return trace;
}

TradeoffRow run_setting(const Scene& scene, const TradeoffSetting& setting,
                        const std::vector<Trajectory>& motions, const ReferenceTrace& reference) {
  const Scene varied = scene_with(scene, setting);
  if (motions.size() != varied.tools.size() || reference.positions.empty() ||
      reference.positions.front().size() != varied.tools.size())
    throw Error("tradeoff: the reference, the motions and the scene's tools do not match");
  TradeoffRow row;
  row.setting = setting;

  const Stopwatch precompute;
  const Model model = build_model(varied);
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(body.free_factor, body.dofs,
                            compliance_row_nodes(body, !varied.obstacles.empty()));
  prepare_compliance(body, columns, std::nullopt);
  row.precompute_s = precompute.elapsed_ms() / 1000;
  row.nodes = body.mesh.node_count();
  row.tets = body.mesh.tet_count();

  SimulationOptions options;
  options.ir = ir_build_options(varied.haptic);
  options.ir.precision = setting.precision;
  options.ir.force_limit =
      std::numeric_limits<double>::infinity();  // compare the physics, not the limiter
  Simulation simulation(body, model.obstacles, columns, varied.tools, options);
  FullSolve own_mesh(body, setting.contact_model, model.obstacles);
  std::vector<PressedTool> pressed(varied.tools.size());

  const int per_step = samples_per(reference.sample_rate_hz, kSimulationRateHz, "simulation rate");
  const int per_tick = samples_per(reference.sample_rate_hz, setting.haptic_rate_hz, "haptic rate");
  const std::size_t users = varied.tools.size();
  std::vector<std::shared_ptr<const PreparedIR>> published(users);
  std::vector<EvaluationState> client_states(users);  // each published IR's, as a client keeps it
  std::vector<double> last_published(users, -INFINITY);
  std::vector<Eigen::Vector3d> held(users, Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> remotes;
  TradeoffTally tally;
  // As the server: compliance rows, B truncation or not.
  TradeoffWireBytes wire_bytes(body, columns, users);
  const std::size_t samples = reference.positions.size();
  for (std::size_t j = 0; j < samples; ++j) {
    const double t = static_cast<double>(j) / reference.sample_rate_hz;
    const std::vector<Eigen::Vector3d>& positions = reference.positions[j];
    if (j % static_cast<std::size_t>(per_step) == 0) {
      for (std::size_t u = 0; u < users; ++u)
        simulation.set_tool(static_cast<int>(u), positions[u]);
      const Stopwatch step;
      const StepReport report = simulation.step(t);
      tally.step(report, step.elapsed_ms());
      for (std::size_t u = 0; u < users; ++u) {
        const std::shared_ptr<const PreparedIR> ir = simulation.ir(static_cast<int>(u));
        const bool due =
            setting.ir_rate_hz <= 0 || t - last_published[u] >= 1 / setting.ir_rate_hz - 1e-9;
        if (ir && ir != published[u] && due) {
          published[u] = ir;
          client_states[u] = make_evaluation_state(*ir);
          last_published[u] = t;
          tally.published(wire_bytes.published(ir->ir, u));
        }
      }
    }
    if (j % static_cast<std::size_t>(per_tick) == 0)
      for (std::size_t u = 0; u < users; ++u) {
        if (!published[u]) continue;
        remotes.clear();
        for (int r = 0; r < remote_count(published[u]->ir); ++r)
          remotes.push_back(positions[remote_user(published[u]->ir, r)]);
        const Stopwatch evaluation;
        // The condensed FEM body ignores dt; under the sphere model its state keeps the contact
        // solve.
        held[u] = evaluate_force(*published[u], client_states[u], positions[u], remotes, 0).force;
        tally.evaluation(1000 * evaluation.elapsed_ms());
      }
    for (std::size_t u = 0; u < users; ++u) pressed[u] = {positions[u], varied.tools[u].radius};
    const std::vector<Eigen::Vector3d> own_forces =
        own_mesh.forces(pressed, held_nodes(simulation));
    for (std::size_t u = 0; u < users; ++u)
      tally.sample(held[u], reference.forces[j][u], own_forces[u]);
  }
  tally.finish(row, reference, users);
  row.memory_mb = model_memory_mb(body, columns);
  return row;
}

std::vector<bool> pareto_front(const std::vector<double>& error, const std::vector<double>& cost) {
  std::vector<bool> front(error.size(), true);
  for (std::size_t i = 0; i < error.size(); ++i)
    for (std::size_t j = 0; j < error.size() && front[i]; ++j)
      if (j != i && error[j] <= error[i] && cost[j] <= cost[i] &&
          (error[j] < error[i] || cost[j] < cost[i]))
        front[i] = false;
  return front;
}

namespace {

std::string front_names(const std::vector<TradeoffRow>& rows, const std::vector<bool>& front) {
  std::string names;
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (front[i]) names += (names.empty() ? "" : ", ") + rows[i].setting.name();
  return names;
}

void write_csv(const std::filesystem::path& file, const std::vector<TradeoffRow>& rows,
               const std::vector<bool>& cpu_front, const std::vector<bool>& bytes_front) {
  AtomicFile out(file);
  out.write(
      "setting,knob,value,nodes,tets,error_rms_pct,error_max_pct,own_mesh_error_rms_pct,own_mesh_"
      "error_max_pct,"
      "precompute_s,mtilde_ms_p50,mtilde_ms_p99,evaluation_us,ir_bytes_per_s,memory_mb,cpu_ms_per_"
      "s,irs_sent,front_cpu,"
      "front_bytes\n");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const TradeoffRow& r = rows[i];
    out.print(
        "{},{},{},{},{},{:.4g},{:.4g},{:.4g},{:.4g},{:.4g},{:.4g},{:.4g},{:.4g},{:.6g},{:.4g},{:."
        "4g},{},{},{}\n",
        r.setting.name(), r.setting.knob, r.setting.value, r.nodes, r.tets, 100 * r.error_rms,
        100 * r.error_max, 100 * r.own_mesh_error_rms, 100 * r.own_mesh_error_max, r.precompute_s,
        r.mtilde_ms_p50, r.mtilde_ms_p99, r.evaluation_us, r.ir_bytes_per_s, r.memory_mb,
        r.cpu_ms_per_s, r.irs_sent, cpu_front[i] ? 1 : 0, bytes_front[i] ? 1 : 0);
  }
  out.commit();
}

void write_markdown(const std::filesystem::path& file, const std::string& heading,
                    const std::vector<TradeoffRow>& rows, const std::vector<bool>& cpu_front,
                    const std::vector<bool>& bytes_front) {
  AtomicFile out(file);
  out.write(heading);
  out.write(
      "\n| setting | nodes | error RMS % | error max % | own-mesh error RMS / max % | precompute s "
      "| M~ ms p50 / p99 "
      "| eval µs | IR kB/s | memory MB | CPU ms/s | front "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const TradeoffRow& r = rows[i];
    std::string front = cpu_front[i] ? "CPU" : "";
    if (bytes_front[i]) front += front.empty() ? "bytes" : ", bytes";
    out.print(
        "| {} | {} | {:.2f} | {:.2f} | {:.3g} / {:.3g} | {:.2f} | {:.2f} / {:.2f} | {:.2f} | "
        "{:.1f} | {:.1f} | {:.1f} | {} |\n",
        r.setting.name(), r.nodes, 100 * r.error_rms, 100 * r.error_max, 100 * r.own_mesh_error_rms,
        100 * r.own_mesh_error_max, r.precompute_s, r.mtilde_ms_p50, r.mtilde_ms_p99,
        r.evaluation_us, r.ir_bytes_per_s / 1000, r.memory_mb, r.cpu_ms_per_s, front);
  }
  out.print(
      "\nOn the front of error against CPU: {}.\n\nOn the front of error against IR bytes: {}.\n",
      front_names(rows, cpu_front), front_names(rows, bytes_front));
  out.commit();
}

void write_pareto_plot(const std::filesystem::path& file, const std::vector<TradeoffRow>& rows,
                       const std::string& x_label, double (*cost)(const TradeoffRow&),
                       const std::vector<bool>& front) {
  LinePlot plot;
  plot.title = "Force error against cost (one point per setting; the front joined)";
  plot.x_label = x_label;
  plot.y_label = "force error RMS, % of peak";
  std::vector<std::pair<double, double>> front_points;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    plot.series.push_back(
        {rows[i].setting.name(), {cost(rows[i])}, {100 * rows[i].error_rms}, "", true});
    if (front[i]) front_points.emplace_back(cost(rows[i]), 100 * rows[i].error_rms);
  }
  std::sort(front_points.begin(), front_points.end());
  Series line{"Pareto front", {}, {}, "black", false};
  for (const auto& [x, y] : front_points) {
    line.x.push_back(x);
    line.y.push_back(y);
  }
  plot.series.push_back(line);
  write_svg(file, plot);
}

// The table, the CSV and the Pareto plots of `rows` under `heading`, in options.out.
void write_tradeoff_results(const TradeoffOptions& options, const std::string& heading,
                            const std::vector<TradeoffRow>& rows) {
  std::vector<double> error, cpu, bytes;
  for (const TradeoffRow& r : rows) {
    error.push_back(r.error_rms);
    cpu.push_back(r.cpu_ms_per_s);
    bytes.push_back(r.ir_bytes_per_s);
  }
  const std::vector<bool> cpu_front = pareto_front(error, cpu);
  const std::vector<bool> bytes_front = pareto_front(error, bytes);
  write_csv(options.out / "tradeoff.csv", rows, cpu_front, bytes_front);
  write_markdown(options.out / "tradeoff.md", heading, rows, cpu_front, bytes_front);
  write_pareto_plot(
      options.out / "pareto_cpu.svg", rows, "CPU per second of session, ms",
      [](const TradeoffRow& r) { return r.cpu_ms_per_s; }, cpu_front);
  write_pareto_plot(
      options.out / "pareto_bytes.svg", rows, "IR traffic, bytes per second",
      [](const TradeoffRow& r) { return r.ir_bytes_per_s; }, bytes_front);
  spdlog::info("front (error against CPU): {}", front_names(rows, cpu_front));
  spdlog::info("front (error against IR bytes): {}", front_names(rows, bytes_front));
  spdlog::info("wrote {}/tradeoff.csv, tradeoff.md, pareto_cpu.svg, pareto_bytes.svg",
               options.out.string());
}

std::string motion_names(const TradeoffOptions& options) {
  std::string names;
  for (const auto& file : options.motions)
    names += (names.empty() ? "" : ", ") + file.filename().string();
  return names;
}

// A home_spring scene beside its FEM twin (--reference-scene): one row per model on the
// same pokes, both against the twin's full solve.
int run_model_comparison(const Scene& scene, const std::vector<Trajectory>& motions,
                         const TradeoffOptions& options) {
  if (options.reference_scene.empty())
    throw Error(fmt::format(
        "{}: a home_spring scene is compared with the same tissue as a linear elastic body: give "
        "its scene as --reference-scene",
        options.scene.string()));
  const Scene fem = load_scene(options.reference_scene);
  single_elastic_object(fem);  // throws naming the scene when it is not one linear elastic object
  if (fem.tools.size() != scene.tools.size())
    throw Error(fmt::format("{}: the FEM scene has {} tools, the scene {}",
                            options.reference_scene.string(), fem.tools.size(),
                            scene.tools.size()));
  const int per_step = samples_per(options.sample_rate_hz, kSimulationRateHz, "simulation rate");
  const int per_tick =
      samples_per(options.sample_rate_hz, scene.haptic.rate_hz, "scene's haptic rate");
  samples_per(options.sample_rate_hz, fem.haptic.rate_hz, "FEM scene's haptic rate");
  TradeoffSetting fem_setting = tradeoff_grid(fem, {}).front();
  fem_setting.knob = "model";
  fem_setting.value = "linear_elastic";
  spdlog::info("reference: {} solved in full at {:g} Hz over the motions ...",
               options.reference_scene.string(), options.sample_rate_hz);
  const ReferenceTrace reference =
      reference_trace(scene_with(fem, fem_setting), motions, options.sample_rate_hz);
  std::vector<TradeoffRow> rows = {
      run_setting(fem, fem_setting, motions, reference),
      run_home_spring_setting(scene, motions, reference, per_step, per_tick)};
  for (const TradeoffRow& r : rows)
    spdlog::info(
        "{}: error RMS {:.2f} % (max {:.2f} %; own model {:.3g} %), eval {:.2f} us, {:.1f} kB/s, "
        "CPU {:.2f} ms/s",
        r.setting.name(), 100 * r.error_rms, 100 * r.error_max, 100 * r.own_mesh_error_rms,
        r.evaluation_us, r.ir_bytes_per_s / 1000, r.cpu_ms_per_s);
  write_tradeoff_results(
      options,
      fmt::format("# The laparoscopy tissue's two models: {} against {}\n\nReference: {} ({} "
                  "nodes, {} tetrahedra), "
                  "full sparse solve at {:g} Hz; peak force {:.3f} N. Workload: {}. The "
                  "home-spring row's own-mesh "
                  "columns are against its own model solved at every sample.\n",
                  scene.name, fem.name, options.reference_scene.filename().string(),
                  reference.nodes, reference.tets, options.sample_rate_hz, reference.peak_force,
                  motion_names(options)),
      rows);
  return 0;
}

}  // namespace

int run_tradeoff(const TradeoffOptions& options) {
  const Scene scene = load_scene(options.scene);
  std::vector<Trajectory> motions;
  for (const auto& file : options.motions) motions.push_back(load_trajectory(file));
  if (motions.size() != scene.tools.size())
    throw Error(fmt::format("{}: the scene has {} tools; give one --motion per tool (got {})",
                            options.scene.string(), scene.tools.size(), motions.size()));
  std::filesystem::create_directories(options.out);
  if (scene.objects.size() == 1 &&
      std::holds_alternative<MassSpringObjectSpec>(scene.objects.front().body))
    return run_mass_spring_tradeoff(scene, motions, options);
  if (scene.objects.size() == 1 &&
      std::holds_alternative<HomeSpringObjectSpec>(scene.objects.front().body))
    return run_model_comparison(scene, motions, options);
  if (!options.reference_scene.empty() && single_elastic_object(scene).mesh.box)
    throw Error(fmt::format(
        "{}: a box scene's reference is its own box at --reference-divisions; --reference-scene is "
        "for mesh files",
        options.scene.string()));

  // Check the rates before the (long) reference: the simulation's and the scene's haptic
  // rate must divide the comparison grid.
  samples_per(options.sample_rate_hz, kSimulationRateHz, "simulation rate");
  samples_per(options.sample_rate_hz, scene.haptic.rate_hz, "scene's haptic rate");
  const std::vector<TradeoffSetting> grid =
      only_knobs(tradeoff_grid(scene, options.divisions, options.sample_rate_hz), options.knobs);
  TradeoffSetting reference_setting = tradeoff_grid(scene, {}).front();
  if (single_elastic_object(scene).mesh.box)
    reference_setting.divisions = options.reference_divisions;
  const Scene reference_scene =
      options.reference_scene.empty()
          ? scene_with(scene, reference_setting)
          : scene_with(load_scene(options.reference_scene), reference_setting);
  if (reference_scene.tools.size() != scene.tools.size())
    throw Error(fmt::format("{}: the reference scene has {} tools, the scene {}",
                            options.reference_scene.string(), reference_scene.tools.size(),
                            scene.tools.size()));
  spdlog::info("reference: {}, solved in full at {:g} Hz over the motions ...",
               single_elastic_object(scene).mesh.box
                   ? fmt::format("{} divisions", options.reference_divisions)
               : options.reference_scene.empty() ? std::string("the scene's own mesh")
                                                 : options.reference_scene.string(),
               options.sample_rate_hz);
  const ReferenceTrace reference =
      reference_trace(reference_scene, motions, options.sample_rate_hz);
  spdlog::info(
      "reference: {} nodes, {} tetrahedra, {} samples, {} contact sets factored, peak force {:.3f} "
      "N, {:.1f} s",
      reference.nodes, reference.tets, reference.positions.size(), reference.factorisations,
      reference.peak_force, reference.seconds);

  std::vector<TradeoffRow> rows;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const Stopwatch watch;
    rows.push_back(run_setting(scene, grid[i], motions, reference));
    const TradeoffRow& r = rows.back();
    spdlog::info(
        "[{}/{}] {}: error RMS {:.2f} % (max {:.2f} %; own mesh {:.3g} %), M~ p99 {:.2f} ms, "
        "{:.1f} kB/s, "
        "CPU {:.1f} ms/s ({:.1f} s)",
        i + 1, grid.size(), r.setting.name(), 100 * r.error_rms, 100 * r.error_max,
        100 * r.own_mesh_error_rms, r.mtilde_ms_p99, r.ir_bytes_per_s / 1000, r.cpu_ms_per_s,
        watch.elapsed_ms() / 1000);
  }

  const std::string heading = fmt::format(
      "# Speed against accuracy: {}\n\nReference: {} nodes, {} tetrahedra, full sparse solve at "
      "{:g} Hz; peak force "
      "{:.3f} N. Workload: {}.\n",
      scene.name, reference.nodes, reference.tets, options.sample_rate_hz, reference.peak_force,
      motion_names(options));
  write_tradeoff_results(options, heading, rows);
  return 0;
}

LabCommand add_tradeoff_command(CLI::App& lab) {
  auto options = std::make_shared<TradeoffOptions>();
  CLI::App* command = lab.add_subcommand("tradeoff",
                                         "Measure what each speed/accuracy setting costs and buys "
                                         "on a scene, against the full solve on its "
                                         "finest mesh (a mass-spring scene: against the server's "
                                         "whole network at the haptic rate; a home_spring "
                                         "scene: a row beside its FEM twin's, given as "
                                         "--reference-scene, both against the twin's full solve): "
                                         "tradeoff.csv, tradeoff.md and Pareto plots in --out");
  command->add_option("--scene", options->scene, "Scene file (YAML)")
      ->required()
      ->check(CLI::ExistingFile);
  command
      ->add_option("--motion", options->motions,
                   "Trajectory file for each scene tool, in order (repeat)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--out", options->out, "Output directory")->required();
  command->add_option("--divisions", options->divisions, "Mesh resolutions to measure (box scenes)")
      ->capture_default_str();
  command
      ->add_option("--reference-divisions", options->reference_divisions,
                   "Resolution of the reference mesh (box scenes)")
      ->capture_default_str()
      ->check(CLI::Range(2, 60));
  command
      ->add_option("--reference-scene", options->reference_scene,
                   "Mesh-file scenes: the same scene on a finer mesh, the reference (default: the "
                   "scene itself); a "
                   "home_spring scene: the same tissue as a linear elastic body (required)")
      ->check(CLI::ExistingFile);
  command
      ->add_option("--sample-rate-hz", options->sample_rate_hz,
                   "The comparison grid; haptic rates that do not divide it are left out")
      ->capture_default_str()
      ->check(CLI::Range(1000.0, 100000.0));
  command->add_option("--knob", options->knobs,
                      "Measure only the baseline and this knob's settings (repeat; e.g. "
                      "boundary_truncation; default: "
                      "every knob)");
  return {command, [options] { return run_tradeoff(*options); }};
}

}  // namespace cohaptic
