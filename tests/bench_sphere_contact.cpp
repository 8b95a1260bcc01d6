// The sphere contact model's cost, each method beside the naive one, in the same run
// (tests/sphere_contact_tables.sh prints them as tables; make bench-sphere):
//   BM_SphereTick/incremental/<contacts>  one haptic tick (evaluate_force) on the IR's normal
//                            compliance W, its contact solve kept from tick to tick
//                            (incremental_contact_solve.h), under the default work budget
//   BM_SphereTick/dense/<contacts>  the same tick done densely from the condensed compliance:
//                            A = N^T L~ N formed every tick over the working set from the
//                            3x3 blocks of L~, and
//                            solve_unilateral_over_candidates, which factors A_SS afresh in
//                            every pass (warm started from the last tick's set, no budget)
//   BM_SphereStep/incremental/400  the server's state solve, SphereStateSolve::solve over the
//                            user's patch (W and its contact solve kept from step to step)
//   BM_SphereStep/condensed/400  the same state solved by condensation, over every touchable
//                            node: the working set condensed over B, M_CC inverted,
//                            A = N^T L~ N and solve_unilateral_contact, the set grown until no
//                            other candidate penetrates (condensed_state_solve below); it takes
//                            seconds, so it runs three times
//   BM_SphereStep/simulation/400  a whole Simulation::step with the new solve: the state, the
//                            patch check, and the IR rebuilt when the patch changes
//   BM_PrepareIr/sphere/<contacts>  what a client does once per IR received
// <contacts> is about how many nodes the sphere pushes: 50, 200 and 400, and 700, whose IR
// holds over 1000 candidates (the most a client must hold a tool).
// The tool moves every tick (or step) along one path, 2 um sideways and 0.5 um deeper a
// tick, back and forth, so that nodes join and leave the contact now and then, as under a hand.
// Counters: contacts, the nodes pushed at the path's start; candidates, the IR's row nodes
// (for the server's solves, their candidates); p99_us, the 99th percentile of the
// iterations' wall times (Google Benchmark reports means; a haptic deadline is about the
// slow ticks);
// unresolved, ticks past the evaluator's work budget (kSphereSolveWork; their force is
// zero); rebuilt, the share of steps that rebuilt the IR; difference, the largest relative
// difference between the two methods' forces found by the check below.
// The body is scenes/block/block.geo graded to 0.4 mm under a 20 mm sphere, B empty (no
// obstacle, no step delay): L~ is L. Before timing, each setting checks that both methods
// give the same force to 1e-9 at points along the path, and fails with an error if not. The
// set-up (gmsh, the touchable nodes' compliance) is cached on disk: one to two minutes the first
// time, seconds after. BLAS runs on one thread, as in the server.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "common/condense/dof_blocks.h"
#include "common/contact/unilateral_contact_solve.h"
#include "common/contact/working_set_contact_solve.h"
#include "common/ir/evaluate_force.h"
#include "common/model/compliance_setup.h"
#include "common/model/model.h"
#include "common/scene/load_scene.h"
#include "common/sim/simulation.h"
#include "common/sim/sphere_state_solve.h"
#include "common/util/blas_threads.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kRadius = 0.02;     // the sphere [m]
constexpr double kAgreement = 1e-9;  // relative force difference allowed between the methods

// The block of scenes/block/two_spheres.yaml, graded to 0.4 mm at (-25, 0, 0), touchable
// within 12 mm of that point: the largest setting's patch reaches about 9 mm from it.
constexpr const char* kSceneYaml = R"(
units: mm
objects:
  - name: block
    mesh: {gmsh: block.geo, set: {fine: 0.4}}
    material: {model: linear_elastic, youngs_modulus: 1.0e5, poisson_ratio: 0.3}
    fixed:
      - plane: {point: [0, 0, -100], normal: [0, 0, 1]}
        axes: xyz
    touchable:
      - box: {min: [-37, -12, -0.01], max: [-13, 12, 0.01]}
    compliance: {precompute: touchable, disk_cache: true}
tools:
  - {name: A, shape: sphere, radius: 20}
haptic: {force_limit: 1000, contact_model: sphere, patch_rings: 1}
)";

// A setting: how deep the sphere starts [m] for about `contacts` pushed nodes.
struct SphereCase {
  int contacts;
  double depth;
};
constexpr std::array kCases{SphereCase{50, 0.104e-3}, SphereCase{200, 0.42e-3},
                            SphereCase{400, 0.86e-3}, SphereCase{700, 1.75e-3}};
constexpr int kStepContacts = 400;

const SphereCase& case_of(int contacts) {
  return *std::find_if(kCases.begin(), kCases.end(),
                       [&](const SphereCase& c) { return c.contacts == contacts; });
}

Eigen::Vector3d start_of(const SphereCase& c) { return {-0.025, 0, kRadius - c.depth}; }

// The tool on its path at tick (or step) `tick`: 0.2 mm sideways and 0.05 mm deeper over
// 100 ticks, then back.
Eigen::Vector3d along_path(const Eigen::Vector3d& start, std::size_t tick) {
  const auto phase = static_cast<double>(tick % 200);
  const double s = (phase <= 100 ? phase : 200 - phase) / 100;
  return start + s * Eigen::Vector3d(1.6e-4, 1.2e-4, -5e-5);
}

double relative_difference(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double scale = std::max(a.norm(), b.norm());
  return scale > 0 ? (a - b).norm() / scale : 0.0;
}

// Per-iteration wall times of one benchmark run, for their 99th percentile.
class IterationTimes {
 public:
  explicit IterationTimes(const benchmark::State& state) {
    times_.reserve(static_cast<std::size_t>(state.max_iterations));
  }
  template <class Work>
  void time(Work&& work) {
    const auto start = std::chrono::steady_clock::now();
    work();
    times_.push_back(
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
            .count());
  }
  double p99_us() {
    if (times_.empty()) return 0;
    const auto rank =
        static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(times_.size()))) - 1;
    std::nth_element(times_.begin(), times_.begin() + static_cast<std::ptrdiff_t>(rank),
                     times_.end());
    return times_[rank];
  }

 private:
  std::vector<double> times_;
};

struct BlockRig {
  std::unique_ptr<Model> model;
  const ElasticBody& body;
  std::unique_ptr<ComplianceColumns> columns;
  std::unordered_map<std::int64_t, int> node_of_tag;
  std::vector<int> touchable;  // the touchable triangles' nodes: the condensed solve's candidates

  BlockRig()
      : model(std::make_unique<Model>(build_model(parse_scene(
            kSceneYaml, COHAPTIC_SOURCE_DIR "/scenes/block/bench_sphere_contact.yaml")))),
        body(single_elastic_body(*model)),
        columns(std::make_unique<ComplianceColumns>(body.free_factor, body.dofs,
                                                    compliance_row_nodes(body, false))),
        touchable(triangle_nodes(body.surface, body.touchable_triangles)) {
    prepare_compliance(body, *columns, default_cache_directory());
    for (int node = 0; node < body.mesh.node_count(); ++node)
      node_of_tag[body.mesh.node_tags[static_cast<std::size_t>(node)]] = node;
  }
  std::vector<int> row_nodes(const CondensedFemIr& ir) const {
    std::vector<int> nodes;
    for (int i = 0; i < ir.row_node_count; ++i)
      nodes.push_back(node_of_tag.at(ir.node_ids[static_cast<std::size_t>(i)]));
    return nodes;
  }
};

BlockRig& block_rig() {
  static BlockRig rig;
  return rig;
}

// The server's simulation with the sphere at `start`, stepped once there.
std::unique_ptr<Simulation> simulation_at(const Eigen::Vector3d& start) {
  BlockRig& rig = block_rig();
  SimulationOptions options;
  options.ir.contact_model = ContactModel::sphere;
  options.ir.patch_rings = 1;
  options.ir.force_limit = kInfinity;
  auto simulation = std::make_unique<Simulation>(rig.body, rig.model->obstacles, *rig.columns,
                                                 rig.model->scene.tools, options);
  simulation->set_tool(0, start);
  simulation->step(0);
  if (!simulation->condensation().boundary_nodes().empty())
    throw Error("the block holds boundary nodes: L~ is not L");
  return simulation;
}

// The dense tick: every row node the sphere reaches is
// a candidate with q = g + q0, and A_ij = n_i^T L~_ij n_j is formed against the working set
// only, from L~ over the row nodes' dofs (3 a node, a fixed axis's rows and columns zero).
class DenseTick {
 public:
  DenseTick(const IntermediateRepresentation& envelope, const Eigen::MatrixXd& compliance)
      : ir_(condensed_fem(envelope)),
        compliance_(compliance),
        radius_(envelope.tool_radius),
        capacity_(static_cast<std::size_t>(ir_.row_node_count)),
        warm_(capacity_, 0),
        node_(capacity_),
        active_(capacity_),
        member_active_(capacity_),
        in_set_(capacity_),
        members_(capacity_),
        order_(capacity_),
        q_(ir_.row_node_count),
        lambda_(ir_.row_node_count),
        scratch_{{}, {}, {}, {}, members_, member_active_, order_, in_set_} {}

  // The force on the tool at `tool`; `pushed` receives the count of pushed nodes.
  std::optional<Eigen::Vector3d> force(const Eigen::Vector3d& tool, int* pushed = nullptr) {
    const SphereContactIr& sphere = *ir_.sphere;
    const SphereTool own{tool, radius_};
    int m = 0;
    for (int i = 0; i < ir_.row_node_count; ++i) {
      if (sphere.normals.col(i).squaredNorm() == 0) continue;
      const double gap = sphere_gap(ir_.rest_positions.col(i), sphere.normals.col(i), own);
      if (!std::isfinite(gap)) continue;
      node_[static_cast<std::size_t>(m)] = i;
      q_[m] = gap + sphere.free_clearance[i];
      active_[static_cast<std::size_t>(m)] = warm_[static_cast<std::size_t>(i)];
      ++m;
    }
    const auto entry = [&](int a, int b) {
      const int i = node_[static_cast<std::size_t>(a)], j = node_[static_cast<std::size_t>(b)];
      return sphere.normals.col(i).dot(compliance_.block<3, 3>(3 * i, 3 * j) *
                                       sphere.normals.col(j));
    };
    const std::span<std::uint8_t> active(active_.data(), static_cast<std::size_t>(m));
    const WorkingSetSolveResult solved = solve_unilateral_over_candidates(
        q_.head(m), entry, [](std::span<const int>) {}, m, active, lambda_.head(m), scratch_,
        kInfinity);
    if (!solved.inner.solved) return std::nullopt;
    std::fill(warm_.begin(), warm_.end(), 0);
    Eigen::Vector3d contact_force = Eigen::Vector3d::Zero();
    int count = 0;
    for (int a = 0; a < m; ++a) {
      const int i = node_[static_cast<std::size_t>(a)];
      warm_[static_cast<std::size_t>(i)] = active[static_cast<std::size_t>(a)];
      if (!(lambda_[a] > 0)) continue;
      contact_force += lambda_[a] * sphere.normals.col(i);
      ++count;
    }
    if (pushed) *pushed = count;
    return -contact_force;
  }

 private:
  const CondensedFemIr& ir_;
  const Eigen::MatrixXd& compliance_;
  double radius_;
  std::size_t capacity_;
  std::vector<std::uint8_t> warm_;  // per row node: active at the last tick
  std::vector<int> node_;           // per candidate: its row node
  std::vector<std::uint8_t> active_, member_active_, in_set_;
  std::vector<int> members_, order_;
  Eigen::VectorXd q_, lambda_;
  WorkingSetScratch<Eigen::MatrixXd, Eigen::VectorXd> scratch_;
};

// One setting's IR as the server built it at the path's start, with L~ over its row nodes.
struct TickRig {
  std::shared_ptr<const PreparedIR> prepared;
  Eigen::MatrixXd compliance;
  Eigen::Vector3d start;
  int contacts = 0;
  double difference = 0;     // the largest relative force difference between the methods
  std::string disagreement;  // empty when both methods gave the same forces
};

// Both methods at every 20th tick of the path's first half (each is exact from any start).
std::string compare_ticks(const TickRig& rig, int& contacts, double& difference) {
  EvaluationState state = make_evaluation_state(*rig.prepared);
  std::get<FemEvaluation>(state.body).sphere->work_budget = kInfinity;
  DenseTick dense(rig.prepared->ir, rig.compliance);
  for (std::size_t tick = 0; tick <= 100; tick += 20) {
    const Eigen::Vector3d tool = along_path(rig.start, tick);
    const ForceSample sample = evaluate_force(*rig.prepared, state, tool, {}, 1e-3);
    int pushed = 0;
    const std::optional<Eigen::Vector3d> expected = dense.force(tool, &pushed);
    if (tick == 0) contacts = pushed;
    if (!expected || (sample.flags & (kContactUnresolved | kNonFinite)))
      return fmt::format("tick {}: a solve failed", tick);
    difference = std::max(difference, relative_difference(sample.force, *expected));
    if (difference > kAgreement)
      return fmt::format(
          "tick {}: the incremental force differs from the dense one by {:.1e} relative", tick,
          difference);
  }
  return {};
}

const TickRig& tick_rig(int contacts) {
  static std::map<int, TickRig> built;
  if (const auto found = built.find(contacts); found != built.end()) return found->second;
  TickRig rig;
  rig.start = start_of(case_of(contacts));
  rig.prepared = simulation_at(rig.start)->ir(0);
  rig.compliance =
      block_rig().columns->gather(block_rig().row_nodes(condensed_fem(rig.prepared->ir)));
  rig.disagreement = compare_ticks(rig, rig.contacts, rig.difference);
  return built.emplace(contacts, std::move(rig)).first->second;
}

// The rig of a setting, or null with the benchmark skipped if it could not be built or
// the methods disagree.
const TickRig* checked_tick_rig(benchmark::State& state, int contacts) {
  try {
    const TickRig& rig = tick_rig(contacts);
    if (rig.disagreement.empty()) return &rig;
    state.SkipWithError(rig.disagreement.c_str());
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
  return nullptr;
}

void size_counters(benchmark::State& state, const TickRig& rig) {
  state.counters["contacts"] = rig.contacts;
  state.counters["candidates"] = condensed_fem(rig.prepared->ir).row_node_count;
}

void BM_SphereTickIncremental(benchmark::State& state, int contacts) {
  const TickRig* rig = checked_tick_rig(state, contacts);
  if (!rig) return;
  EvaluationState evaluation = make_evaluation_state(*rig->prepared);
  IterationTimes times(state);
  std::size_t tick = 0;
  int unresolved = 0;
  for (auto _ : state) {
    const Eigen::Vector3d tool = along_path(rig->start, tick++);
    times.time([&] {
      const ForceSample sample = evaluate_force(*rig->prepared, evaluation, tool, {}, 1e-3);
      unresolved += (sample.flags & kContactUnresolved) != 0;
      benchmark::DoNotOptimize(sample.force.data());
    });
  }
  size_counters(state, *rig);
  state.counters["p99_us"] = times.p99_us();
  state.counters["unresolved"] = unresolved;
}

void BM_SphereTickDense(benchmark::State& state, int contacts) {
  const TickRig* rig = checked_tick_rig(state, contacts);
  if (!rig) return;
  DenseTick dense(rig->prepared->ir, rig->compliance);
  IterationTimes times(state);
  std::size_t tick = 0;
  for (auto _ : state) {
    const Eigen::Vector3d tool = along_path(rig->start, tick++);
    times.time([&] {
      const std::optional<Eigen::Vector3d> force = dense.force(tool);
      benchmark::DoNotOptimize(force);
    });
  }
  size_counters(state, *rig);
  state.counters["p99_us"] = times.p99_us();
  state.counters["difference"] = rig->difference;
}

void BM_PrepareSphereIr(benchmark::State& state, int contacts) {
  const TickRig* rig = checked_tick_rig(state, contacts);
  if (!rig) return;
  for (auto _ : state) {
    const PreparedIR again = prepare_ir(rig->prepared->ir);
    benchmark::DoNotOptimize(again.condition_estimate);
  }
  size_counters(state, *rig);
}

// The condensed state solve: the candidates' working set
// K, first the nodes the spheres hold at rest, is condensed over B (M_CC and M_CB), M_CC
// inverted back to L~ (LLT), A = N^T L~ N and q = g + N^T u0 formed, and the unilateral
// problem solved afresh; every other candidate that the solved state carries into its
// sphere joins K, and K is solved again, until none does.
StateSolution condensed_state_solve(ComplianceColumns& columns,
                                    IncrementalCondensation& condensation, const ElasticBody& body,
                                    std::span<const int> candidates,
                                    std::span<const SphereTool> spheres,
                                    const Eigen::VectorXd& boundary_displacement) {
  const DofMap& dofs = body.dofs;
  std::vector<int> free_candidates;
  for (int node : candidates)
    if (!condensation.in_boundary(node)) free_candidates.push_back(node);
  const SphereCandidates all =
      sphere_candidates(body.mesh, dofs, body.contact_normals, free_candidates, spheres);

  std::vector<bool> in_set(all.nodes.size());
  for (std::size_t i = 0; i < all.nodes.size(); ++i) in_set[i] = all.constraints[i].gap < 0;
  for (;;) {
    SphereCandidates set;
    std::vector<std::size_t> others;
    for (std::size_t i = 0; i < all.nodes.size(); ++i)
      if (in_set[i]) {
        set.nodes.push_back(all.nodes[i]);
        set.constraints.push_back(all.constraints[i]);
      } else {
        others.push_back(i);
      }

    StateSolution state;
    state.tool_forces.assign(spheres.size(), Eigen::Vector3d::Zero());
    const auto m = static_cast<Eigen::Index>(set.nodes.size());
    state.contact_dofs = free_dofs_of_nodes(dofs, set.nodes);
    state.contact_forces =
        Eigen::VectorXd::Zero(static_cast<Eigen::Index>(state.contact_dofs.size()));
    if (m > 0) {
      const CondensedOperator op = condensation.condense(set.nodes);
      const Eigen::LLT<Eigen::MatrixXd> llt(op.m_cc);
      if (llt.info() != Eigen::Success)
        throw NumericalError("the sphere contact's M_CC is not positive definite");
      const Eigen::MatrixXd compliance =
          llt.solve(Eigen::MatrixXd::Identity(op.m_cc.rows(), op.m_cc.cols()));
      const Eigen::VectorXd free_displacement = -compliance * (op.m_cb * boundary_displacement);
      Eigen::MatrixXd normals =
          Eigen::MatrixXd::Zero(compliance.rows(), m);  // N over the condensed rows
      for (Eigen::Index i = 0, row = 0; i < m; ++i)
        for (int axis = 0; axis < 3; ++axis)
          if (!dofs.is_fixed(set.nodes[static_cast<std::size_t>(i)], axis))
            normals(row++, i) = set.constraints[static_cast<std::size_t>(i)].normal[axis];
      Eigen::MatrixXd a = normals.transpose() * compliance * normals;
      a = 0.5 * (a + a.transpose()).eval();
      Eigen::VectorXd q = normals.transpose() * free_displacement;
      for (Eigen::Index i = 0; i < m; ++i) q[i] += set.constraints[static_cast<std::size_t>(i)].gap;

      std::vector<std::uint8_t> active(static_cast<std::size_t>(m));
      for (Eigen::Index i = 0; i < m; ++i) active[static_cast<std::size_t>(i)] = q[i] < 0;
      Eigen::VectorXd pushes(m);
      Eigen::MatrixXd factor(m, m);
      std::vector<int> order(static_cast<std::size_t>(m));
      if (!solve_unilateral_contact(a, q, active, pushes, factor, order, kInfinity).solved)
        throw NumericalError("the sphere contact's normal compliance is not positive definite");
      state.contact_forces = normals * pushes;
      for (Eigen::Index i = 0; i < m; ++i) {
        const SphereConstraint& c = set.constraints[static_cast<std::size_t>(i)];
        state.tool_forces[static_cast<std::size_t>(c.tool)] += pushes[i] * c.normal;
      }
    }
    solve_boundary_forces(columns, condensation, dofs, boundary_displacement, state);

    if (others.empty()) return state;
    std::vector<int> other_nodes;
    for (std::size_t i : others) other_nodes.push_back(all.nodes[i]);
    const Eigen::Matrix3Xd u = displacement_of_nodes(columns, state, other_nodes);
    bool joined = false;
    for (std::size_t k = 0; k < others.size(); ++k) {
      const SphereConstraint& c = all.constraints[others[k]];
      if (c.gap + c.normal.dot(u.col(static_cast<Eigen::Index>(k))) < 0)
        in_set[others[k]] = joined = true;
    }
    if (!joined) return state;
  }
}

enum class StepKind { incremental, condensed, simulation };

// The server's side at the 400-contact setting: a simulation for whole steps, and both state
// solves over the user's patch (the incremental one's candidates) or every touchable node
// (the condensed one's).
struct StepRig {
  Eigen::Vector3d start;
  std::unique_ptr<Simulation> simulation;
  std::vector<int> patch;
  std::unique_ptr<IncrementalCondensation> condensation;  // B empty, as in the simulation
  std::unique_ptr<SphereStateSolve> incremental;
  Eigen::VectorXd boundary_displacement;  // none
  // Per StepKind, the next step on the path: the solves that keep a state go on from where
  // the last run left them rather than jump back to the start.
  std::array<std::size_t, 3> next_step{};
  int contacts = 0;
  double difference = 0;  // as TickRig's
  std::string disagreement;
};

// The nodes a state pushes (contact dofs come node by node).
int pushed_nodes(const StateSolution& state) {
  std::vector<int> nodes;
  for (std::size_t i = 0; i < state.contact_dofs.size(); ++i)
    if (state.contact_forces[static_cast<Eigen::Index>(i)] != 0)
      nodes.push_back(state.contact_dofs[i] / 3);
  return static_cast<int>(std::unique(nodes.begin(), nodes.end()) - nodes.begin());
}

std::string compare_steps(StepRig& rig) {
  BlockRig& block = block_rig();
  for (std::size_t step = 0; step <= 100; step += 50) {
    const SphereTool sphere{along_path(rig.start, step), kRadius};
    const StateSolution fresh = rig.incremental->solve(
        *rig.condensation, rig.patch, std::span(&sphere, 1), rig.boundary_displacement);
    const StateSolution condensed =
        condensed_state_solve(*block.columns, *rig.condensation, block.body, block.touchable,
                              std::span(&sphere, 1), rig.boundary_displacement);
    if (step == 0) rig.contacts = pushed_nodes(condensed);
    rig.difference = std::max(rig.difference,
                              relative_difference(fresh.tool_forces[0], condensed.tool_forces[0]));
    if (rig.difference > kAgreement)
      return fmt::format(
          "step {}: the incremental state's force differs from the condensed one's by {:.1e} "
          "relative",
          step, rig.difference);
  }
  rig.next_step[static_cast<std::size_t>(StepKind::incremental)] = 101;
  return {};
}

StepRig& step_rig() {
  static StepRig rig = [] {
    BlockRig& block = block_rig();
    StepRig built;
    built.start = start_of(case_of(kStepContacts));
    built.simulation = simulation_at(built.start);
    built.patch = block.row_nodes(condensed_fem(built.simulation->ir(0)->ir));
    built.condensation = std::make_unique<IncrementalCondensation>(*block.columns, block.body.dofs);
    built.incremental = std::make_unique<SphereStateSolve>(block.body, *block.columns);
    built.disagreement = compare_steps(built);
    return built;
  }();
  return rig;
}

StepRig* checked_step_rig(benchmark::State& state) {
  try {
    StepRig& rig = step_rig();
    if (rig.disagreement.empty()) return &rig;
    state.SkipWithError(rig.disagreement.c_str());
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
  return nullptr;
}

void BM_SphereStep(benchmark::State& state, StepKind kind) {
  StepRig* rig = checked_step_rig(state);
  if (!rig) return;
  BlockRig& block = block_rig();
  IterationTimes times(state);
  std::size_t& step = rig->next_step[static_cast<std::size_t>(kind)];
  int rebuilt = 0;
  for (auto _ : state) {
    const SphereTool sphere{along_path(rig->start, step++), kRadius};
    times.time([&] {
      switch (kind) {
        case StepKind::incremental: {
          StateSolution solved = rig->incremental->solve(
              *rig->condensation, rig->patch, std::span(&sphere, 1), rig->boundary_displacement);
          benchmark::DoNotOptimize(solved.tool_forces[0].data());
          break;
        }
        case StepKind::condensed: {
          StateSolution solved =
              condensed_state_solve(*block.columns, *rig->condensation, block.body, block.touchable,
                                    std::span(&sphere, 1), rig->boundary_displacement);
          benchmark::DoNotOptimize(solved.tool_forces[0].data());
          break;
        }
        case StepKind::simulation:
          rig->simulation->set_tool(0, sphere.centre);
          rebuilt += rig->simulation->step(1e-3 * static_cast<double>(step)).rebuilt;
          break;
      }
    });
  }
  state.counters["contacts"] = rig->contacts;
  state.counters["candidates"] = kind == StepKind::condensed
                                     ? static_cast<double>(block.touchable.size())
                                     : static_cast<double>(rig->patch.size());
  state.counters["p99_us"] = times.p99_us();
  if (kind == StepKind::condensed) state.counters["difference"] = rig->difference;
  if (kind == StepKind::simulation)
    state.counters["rebuilt"] =
        static_cast<double>(rebuilt) / static_cast<double>(state.iterations());
}

void register_sphere_contact_benchmarks() {
  use_single_blas_thread();
  for (const SphereCase& c : kCases) {
    const std::string size = std::to_string(c.contacts);
    benchmark::RegisterBenchmark((std::string("BM_SphereTick/incremental/") + size).c_str(),
                                 BM_SphereTickIncremental, c.contacts)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark((std::string("BM_SphereTick/dense/") + size).c_str(),
                                 BM_SphereTickDense, c.contacts)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark((std::string("BM_PrepareIr/sphere/") + size).c_str(),
                                 BM_PrepareSphereIr, c.contacts)
        ->Unit(benchmark::kMicrosecond);
  }
  for (const auto& [name, kind] : {std::pair{"incremental", StepKind::incremental},
                                   std::pair{"condensed", StepKind::condensed},
                                   std::pair{"simulation", StepKind::simulation}}) {
    const std::string full_name =
        std::string("BM_SphereStep/") + name + "/" + std::to_string(kStepContacts);
    benchmark::internal::Benchmark* step =
        benchmark::RegisterBenchmark(full_name.c_str(), BM_SphereStep, kind)
            ->Unit(benchmark::kMillisecond);
    // The condensed solve takes seconds at this size: a few calls give its spread.
    if (kind == StepKind::condensed) step->Iterations(3);
  }
}

const int sphere_contact_benchmarks_registered = (register_sphere_contact_benchmarks(), 0);

}  // namespace
}  // namespace cohaptic
