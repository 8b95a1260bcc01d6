// Benchmarks of the intermediate representation, naive against incremental in one run:
//   BM_MtildeUpdate/<method>/<|B|>    one boundary node joins (or, next iteration, leaves)
//                                      and M~ is rebuilt for the same contact set; the
//                                      node joins last and leaves from there
//   BM_MtildeUpdate/incremental_oldest/<|B|>  the same, but the node that leaves is the
//                                      oldest of B (first position: the whole factor below
//                                      it is updated), and it joins again at the end
//   (incremental counters: ms per iteration spent on the factor G, the cached Z, S and
//   M_CC, and M_CB; see IncrementalCondensation::Statistics)
//   BM_TriangleChange/<method>/<|B|>  the tool moves to another triangle: M~ for a new C
//   BM_Evaluate/<|B|>                 one haptic tick: the force from a prepared IR with a
//                                      remote tool (counters: IR bytes in f64 and f32)
//   BM_PrepareIr/<|B|>                what a client does once per IR received
// C is a user's patch (one ring around its triangle) plus a remote user's triangle. B is
// the step-delay set nearest the contact. |B| = 0, 150, 300 on the paper's cube (11
// divisions, 584 movable surface nodes); |B| = 1000 on a 16-division cube, the smallest
// whose surface has that many movable nodes. BLAS runs on one thread, as in the server.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <memory>

#include "common/condense/incremental_condensation.h"
#include "common/condense/naive_condensation.h"
#include "common/contact/nearest_surface_nodes.h"
#include "common/scene/load_scene.h"
#include "common/sim/simulation.h"
#include "common/util/blas_threads.h"
#include "support/cube_scene.h"
#include "support/evaluate_static.h"

namespace cohaptic {
namespace {

// A cube model, its compliance over the whole surface, and the sets of one scenario.
struct Fixture {
  std::unique_ptr<Model> model;
  std::unique_ptr<ComplianceColumns> columns;
  const ElasticBody& body() const { return single_elastic_body(*model); }
  std::vector<int> contact;                      // C: patch + remote triangle
  std::vector<int> boundary;                     // B: |B| nodes nearest the contact
  std::vector<int> spare;                        // nodes that join and leave B
  std::vector<std::vector<int>> other_contacts;  // C after a triangle change, cycling
  std::shared_ptr<const PreparedIR> ir_f64, ir_f32;
  Eigen::Vector3d own = Eigen::Vector3d(0.001, 0.002, -0.003),
                  remote = Eigen::Vector3d(0.025, -0.005, -0.003);
};

Fixture& fixture(int boundary_nodes) {
  static std::map<int, std::unique_ptr<Fixture>> fixtures;
  auto& slot = fixtures[boundary_nodes];
  if (slot) return *slot;
  slot = std::make_unique<Fixture>();
  Fixture& f = *slot;
  testing::CubeSceneOptions scene;
  scene.divisions = boundary_nodes > 500 ? 16 : 11;
  f.model = std::make_unique<Model>(
      build_model(parse_scene(testing::cube_scene_yaml(scene), "bench-cube.yaml")));
  f.columns = std::make_unique<ComplianceColumns>(f.body().free_factor, f.body().dofs,
                                                  f.body().surface.nodes);
  const Model& model = *f.model;
  const ElasticBody& body = single_elastic_body(model);

  // Reserved for contacts: the 40 touchable triangles nearest the own tool (the triangle
  // changes cycle through them) and the remote tool's triangle. B avoids them all.
  std::vector<std::pair<double, int>> by_distance;
  for (int t : body.touchable_triangles) {
    const Triangle& tri = body.surface.triangles[t];
    const Eigen::Vector3d centre =
        (body.mesh.nodes.col(tri[0]) + body.mesh.nodes.col(tri[1]) + body.mesh.nodes.col(tri[2])) /
        3;
    by_distance.emplace_back((centre - f.own).norm(), t);
  }
  std::sort(by_distance.begin(), by_distance.end());
  std::vector<bool> reserved(static_cast<std::size_t>(body.mesh.node_count()), false);
  for (std::size_t i = 0; i < 40; ++i) {
    const Triangle& tri = body.surface.triangles[by_distance[i].second];
    f.other_contacts.push_back({tri[0], tri[1], tri[2]});
    for (int node : tri) reserved[node] = true;
  }
  const std::vector<UserTool> tools = {
      {0, f.own, 0, nearest_touchable_triangle(body, f.own), {}},
      {1, f.remote, 0, nearest_touchable_triangle(body, f.remote), {}}};
  for (const UserTool& tool : tools)
    for (int node : body.surface.triangles[tool.nearest_triangle]) reserved[node] = true;
  f.boundary = nearest_surface_nodes(body.mesh, body.surface, body.dofs,
                                     std::vector<Eigen::Vector3d>{f.own}, boundary_nodes, reserved);
  for (int node : f.boundary) reserved[node] = true;
  f.spare = nearest_surface_nodes(body.mesh, body.surface, body.dofs,
                                  std::vector<Eigen::Vector3d>{f.own}, 8, reserved);

  IncrementalCondensation condensation(*f.columns, body.dofs);
  condensation.set_boundary_nodes(f.boundary);
  const std::vector<Eigen::Vector3d> held(f.boundary.size(), Eigen::Vector3d::Zero());
  for (IrPrecision precision : {IrPrecision::f64, IrPrecision::f32}) {
    IrBuildOptions options;
    options.precision = precision;
    auto prepared = std::make_shared<const PreparedIR>(
        prepare_ir(build_ir(body, condensation, tools, 0, held, options, 1, 0)));
    (precision == IrPrecision::f64 ? f.ir_f64 : f.ir_f32) = prepared;
  }
  const CondensedFemIr& ir = condensed_fem(f.ir_f64->ir);
  for (int i = 0; i < ir.row_node_count; ++i)
    f.contact.push_back(node_index_from_tag(body.mesh, ir.node_ids[i]));
  return f;
}

void BM_MtildeUpdate_naive(benchmark::State& state) {
  Fixture& f = fixture(static_cast<int>(state.range(0)));
  std::vector<int> boundary = f.boundary;
  bool joined = false;
  for (auto _ : state) {
    if (joined)
      boundary.pop_back();
    else
      boundary.push_back(f.spare[0]);
    joined = !joined;
    benchmark::DoNotOptimize(
        naive_condensation(*f.columns, f.body().dofs, f.contact, boundary).m_cb.data());
  }
  state.counters["contact_dofs"] = static_cast<double>(condensed_fem(f.ir_f64->ir).m_tilde.rows());
}

// Per-iteration counters: where an incremental update's time goes, and how often the
// drift monitor refactored.
void report_phases(benchmark::State& state, const IncrementalCondensation::Statistics& before,
                   const IncrementalCondensation::Statistics& after) {
  const auto per_iteration = [](double ms) {
    return benchmark::Counter(ms, benchmark::Counter::kAvgIterations);
  };
  state.counters["factor_ms"] = per_iteration(after.factor_ms - before.factor_ms);
  state.counters["z_ms"] = per_iteration(after.z_ms - before.z_ms);
  state.counters["schur_ms"] = per_iteration(after.schur_ms - before.schur_ms);
  state.counters["m_cb_ms"] = per_iteration(after.m_cb_ms - before.m_cb_ms);
  state.counters["refactorizations"] =
      static_cast<double>(after.refactorizations - before.refactorizations);
}

// Odd iterations: `spare` joins B (last). Even ones: the newest node (the spare) leaves,
// or with `oldest` the first node of B leaves and becomes the next spare.
void mtilde_update_incremental(benchmark::State& state, bool oldest) {
  Fixture& f = fixture(static_cast<int>(state.range(0)));
  IncrementalCondensation condensation(*f.columns, f.body().dofs);
  condensation.set_boundary_nodes(f.boundary);
  condensation.condense(f.contact);
  const IncrementalCondensation::Statistics before = condensation.statistics();
  int spare = f.spare[0];
  bool joined = false;
  for (auto _ : state) {
    if (!joined) {
      condensation.add_boundary_node(spare);
    } else {
      if (oldest) spare = condensation.boundary_nodes().front();
      condensation.remove_boundary_node(spare);
    }
    joined = !joined;
    benchmark::DoNotOptimize(condensation.condense(f.contact).m_cb.data());
  }
  report_phases(state, before, condensation.statistics());
  state.counters["contact_dofs"] = static_cast<double>(condensed_fem(f.ir_f64->ir).m_tilde.rows());
}

void BM_MtildeUpdate_incremental(benchmark::State& state) {
  mtilde_update_incremental(state, false);
}
void BM_MtildeUpdate_incremental_oldest(benchmark::State& state) {
  mtilde_update_incremental(state, true);
}

void BM_TriangleChange_naive(benchmark::State& state) {
  Fixture& f = fixture(static_cast<int>(state.range(0)));
  std::size_t next = 0;
  for (auto _ : state) {
    const std::vector<int>& contact = f.other_contacts[next++ % f.other_contacts.size()];
    benchmark::DoNotOptimize(
        naive_condensation(*f.columns, f.body().dofs, contact, f.boundary).m_cb.data());
  }
}

void BM_TriangleChange_incremental(benchmark::State& state) {
  Fixture& f = fixture(static_cast<int>(state.range(0)));
  IncrementalCondensation::Options options;
  options.z_cache_nodes = 16;  // smaller than the 120 nodes cycled: every change is a miss
  IncrementalCondensation condensation(*f.columns, f.body().dofs, options);
  condensation.set_boundary_nodes(f.boundary);
  const IncrementalCondensation::Statistics before = condensation.statistics();
  std::size_t next = 0;
  for (auto _ : state) {
    const std::vector<int>& contact = f.other_contacts[next++ % f.other_contacts.size()];
    benchmark::DoNotOptimize(condensation.condense(contact).m_cb.data());
  }
  report_phases(state, before, condensation.statistics());
}

void BM_Evaluate(benchmark::State& state) {
  Fixture& f = fixture(static_cast<int>(state.range(0)));
  const PreparedIR& prepared = *f.ir_f64;
  Eigen::Vector3d tool = f.own;
  for (auto _ : state) {
    tool.z() = -0.003 - 1e-9 * static_cast<double>(state.iterations() % 1000);
    benchmark::DoNotOptimize(
        testing::evaluate_static(prepared, tool, std::span(&f.remote, 1)).force.data());
  }
  state.counters["ir_bytes_f64"] = static_cast<double>(f.ir_f64->ir.size_bytes());
  state.counters["ir_bytes_f32"] = static_cast<double>(f.ir_f32->ir.size_bytes());
}

void BM_PrepareIr(benchmark::State& state) {
  Fixture& f = fixture(static_cast<int>(state.range(0)));
  for (auto _ : state)
    benchmark::DoNotOptimize(
        std::get<PreparedFem>(prepare_ir(f.ir_f64->ir).body).compliance.data());
}

const std::vector<std::int64_t> kBoundarySizes = {0, 150, 300, 1000};

void register_condensation_benchmarks() {
  // For the whole program, whatever runs first: the server's setting (server/main.cpp).
  use_single_blas_thread();
  const auto add = [](const char* name, void (*fn)(benchmark::State&), benchmark::TimeUnit unit) {
    auto* b = benchmark::RegisterBenchmark(name, fn)->Unit(unit);
    for (std::int64_t size : kBoundarySizes) b->Arg(size);
  };
  add("BM_MtildeUpdate/naive", BM_MtildeUpdate_naive, benchmark::kMillisecond);
  add("BM_MtildeUpdate/incremental", BM_MtildeUpdate_incremental, benchmark::kMillisecond);
  add("BM_MtildeUpdate/incremental_oldest", BM_MtildeUpdate_incremental_oldest,
      benchmark::kMillisecond);
  add("BM_TriangleChange/naive", BM_TriangleChange_naive, benchmark::kMillisecond);
  add("BM_TriangleChange/incremental", BM_TriangleChange_incremental, benchmark::kMillisecond);
  add("BM_Evaluate", BM_Evaluate, benchmark::kMicrosecond);
  add("BM_PrepareIr", BM_PrepareIr, benchmark::kMicrosecond);
}

const int condensation_benchmarks_registered = (register_condensation_benchmarks(), 0);

}  // namespace
}  // namespace cohaptic
