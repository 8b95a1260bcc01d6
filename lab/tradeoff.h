// `cohaptic-lab tradeoff`: what each speed/accuracy setting costs and what it buys.
//
// Every setting replays one fixed workload (a scripted motion per scene tool: press, slide
// across several triangles, release, with a second user pressing nearby) through the same
// code the networked system runs, without sockets: the simulation steps every 1 ms and
// builds IRs (server), each user's haptic loop evaluates its latest IR at the setting's
// haptic rate and holds the force in between (client). The forces are compared, on a
// 10 kHz time grid, with the reference: the finest mesh of the same geometry solved in
// full at the same tool positions, under the baseline's contact model (the sphere model's
// unilateral problem, SphereContactReference; for the paper's two models node translation,
// ContactReference); and, to separate the discretisation from the rest, with the full
// solve of the setting's own contact model (node translation for both of the paper's) on
// the setting's own mesh.
//
// One knob at a time is varied from the scene's own settings (the baseline): mesh
// divisions (box scenes), element formulation, contact model, patch rings, IR precision,
// B truncation (scenes with obstacles, the only ones with held nodes here), IR update
// policy (every set change, or at most R per second), haptic rate. With obstacles the
// references hold the nodes that the simulation's active set puts on them. Costs per setting:
// precompute time, M~ build time (p50/p99 of the steps that rebuilt IRs), evaluation time per tick,
// IR bytes per second as the wire carries them (compliance rows, lab/tradeoff_wire_bytes.h), memory
// (K, its factor, compliance columns) and CPU per second of session (simulation steps +
// evaluations). Units as the column names say.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "common/haptics/trajectory.h"
#include "common/ir/intermediate_representation.h"
#include "common/scene/scene.h"
#include "lab/lab_command.h"

namespace cohaptic {

struct TradeoffSetting {
  std::string knob = "baseline";  ///< which setting differs from the baseline
  std::string value;              ///< its value, as written in the table
  int divisions = 0;              ///< cells along the box's longest side; 0: the scene's mesh
  ElementFormulation formulation = ElementFormulation::linear_tet;
  ContactModel contact_model = ContactModel::node_translation;
  int patch_rings = 1;
  IrPrecision precision = IrPrecision::f64;
  double boundary_truncation = 0;
  double ir_rate_hz = 0;  ///< 0: a new IR on every set change; else at most this many per second
  double haptic_rate_hz = 1000;

  std::string name() const { return knob == "baseline" ? knob : knob + " " + value; }
};

/// The baseline (the scene's settings) and one variation per other value of each knob.
/// `divisions` lists mesh resolutions for box scenes (ignored for mesh files); haptic
/// rates that do not divide `sample_rate_hz` (the comparison grid) are left out.
std::vector<TradeoffSetting> tradeoff_grid(const Scene& scene, const std::vector<int>& divisions,
                                           double sample_rate_hz = 10000);

/// The baseline and the settings of `knobs` in `grid` (all of it if `knobs` is empty);
/// throws Error naming a knob the grid has no setting of.
std::vector<TradeoffSetting> only_knobs(const std::vector<TradeoffSetting>& grid,
                                        const std::vector<std::string>& knobs);

/// The scene with a setting applied (mesh divisions, element, contact model, patch rings,
/// B truncation, haptic rate; the disk cache off, so precompute is measured).
Scene scene_with(const Scene& scene, const TradeoffSetting& setting);

/// The workload's reference: tool positions and forces on a regular time grid.
struct ReferenceTrace {
  double sample_rate_hz = 10000;
  std::vector<std::vector<Eigen::Vector3d>> positions;  ///< [sample][tool], m
  std::vector<std::vector<Eigen::Vector3d>> forces;     ///< [sample][tool], N
  double peak_force = 0;                                ///< max |force| [N]
  int nodes = 0, tets = 0;
  std::size_t factorisations = 0;
  double seconds = 0;  ///< to build the model and solve
};

/// Samples `motions` (one per scene tool) every 1 / sample_rate_hz s and solves the
/// `reference` scene in full at each sample.
ReferenceTrace reference_trace(const Scene& reference, const std::vector<Trajectory>& motions,
                               double sample_rate_hz);

struct TradeoffRow {
  TradeoffSetting setting;
  int nodes = 0, tets = 0;
  double error_rms = 0;  ///< RMS over samples and tools of |F - F_ref|, over the reference's peak
  double error_max = 0;  ///< max of the same, over the peak
  /// The same against the full solve (the sphere model's, or node translation) on the setting's own
  /// mesh, over the same (the reference's) peak, so that both columns share a scale: what the IR
  /// pipeline itself costs in accuracy (patch, update policy, precision, haptic rate, truncation,
  /// contact model), without the discretisation.
  double own_mesh_error_rms = 0, own_mesh_error_max = 0;
  double precompute_s = 0;  ///< model build (assembly, factorisation) + compliance precompute
  double mtilde_ms_p50 = 0, mtilde_ms_p99 = 0;  ///< per step that rebuilt the IRs (all users)
  double evaluation_us = 0;                     ///< per haptic tick and user (median)
  double ir_bytes_per_s = 0;                    ///< IRs sent to all users, per second of workload
  double memory_mb = 0;                         ///< K + factor of K_ff + compliance columns
  /// Simulation steps + evaluations per second of workload: steps that rebuilt IRs as timed,
  /// the others and the evaluations at their median time (robust to scheduler hiccups).
  double cpu_ms_per_s = 0;
  int irs_sent = 0;
};

/// Runs the workload with `setting` against `reference` (sampled from the same motions).
TradeoffRow run_setting(const Scene& scene, const TradeoffSetting& setting,
                        const std::vector<Trajectory>& motions, const ReferenceTrace& reference);

/// Whether each point is on the Pareto front of (error, cost), both to be small: no other
/// point is at least as good in both and better in one.
std::vector<bool> pareto_front(const std::vector<double>& error, const std::vector<double>& cost);

struct TradeoffOptions {
  std::filesystem::path scene;
  std::vector<std::filesystem::path> motions;  ///< one trajectory file per scene tool
  std::filesystem::path out;
  std::vector<int> divisions = {6, 8, 11, 14};  ///< box scenes
  int reference_divisions = 18;                 ///< box scenes
  /// Mesh-file scenes: the same geometry on a finer mesh (empty: the scene itself).
  std::filesystem::path reference_scene;
  double sample_rate_hz = 10000;  ///< the comparison grid; every haptic rate measured divides it
  /// Measure only the baseline and the settings of these knobs (TradeoffSetting::knob); empty: all.
  std::vector<std::string> knobs;
};

/// Writes DIR/tradeoff.csv, DIR/tradeoff.md and DIR/pareto_cpu.svg, DIR/pareto_bytes.svg;
/// logs a progress line per setting. Returns the exit code.
int run_tradeoff(const TradeoffOptions& options);

/// `cohaptic-lab tradeoff --scene FILE --motion FILE... --out DIR [...]`.
LabCommand add_tradeoff_command(CLI::App& lab);

}  // namespace cohaptic
