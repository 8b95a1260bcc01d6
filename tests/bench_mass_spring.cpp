// Benchmarks of the mass-spring body (the thin-objects paper's Table 2 and Sec. 5):
//   BM_MassSpringDeformation/<nodes>   one integrator step of the whole tube (internal forces,
//                                      plane friction, semi-implicit Euler), 180-720 nodes
//   BM_MassSpringCollision/faces/<nodes>  the paper's search: nearest surface node, then the
//                                      faces around it (Sec. 4.2)
//   BM_MassSpringCollision/all_triangles/<nodes>  the naive search: the closest point on
//                                      every surface triangle
//   BM_MassSpringCriticalStep/<density>  the largest stable step (counter critical_ms) at
//                                      the paper's two densities, and the time to find it
//   BM_MassSpringClientTick/<sections>  one haptic tick of a client: the IR's sub-network of
//                                      `sections` free sections a side integrated over 1 ms
//                                      with the tool pressing (counters: nodes, IR bytes)
// The tube is the paper's (radius 5 mm, sections 2.2245 mm apart, E = 737.4 Pa) lying on a
// plane with the noodle scene's frictions; 9 nodes per section.
#include <benchmark/benchmark.h>

#include <limits>
#include <numbers>

#include "common/contact/closest_point_on_triangle.h"
#include "common/ir/build_mass_spring_ir.h"
#include "common/ir/evaluate_force.h"
#include "common/mass_spring/integrate_network.h"
#include "common/mass_spring/stable_time_step.h"
#include "common/mass_spring/surface_collision.h"
#include "common/mass_spring/tube_network.h"
#include "common/model/mass_spring_body.h"

namespace cohaptic {
namespace {

MassSpringObjectSpec paper_tube(int sections, double density) {
  MassSpringObjectSpec spec;
  const double radius = 0.005, spacing = 0.0022245,
               lift = radius * std::cos(std::numbers::pi / kRingNodes);
  spec.tube.centre_line = {Eigen::Vector3d(0, 0, lift),
                           Eigen::Vector3d(spacing * (sections - 1), 0, lift)};
  spec.tube.radius = radius;
  spec.tube.sections = sections;
  spec.material = {737.4, density, 1e-6};
  spec.plane = SupportPlane{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.5, 0.2};
  return spec;
}

MassSpringModel paper_body(int sections, double density = 9049) {
  return build_mass_spring_body("noodle", paper_tube(sections, density), "bench");
}

void BM_MassSpringDeformation(benchmark::State& state) {
  const MassSpringModel body = paper_body(static_cast<int>(state.range(0)) / kSectionNodes);
  MassSpringState network = make_state(body.network);
  for (auto _ : state) {
    step_network(body.network, network, {}, {}, body.network.parameters.time_step);
    benchmark::DoNotOptimize(network.positions.data());
  }
  state.counters["step_ms"] = body.network.parameters.time_step * 1e3;
}
BENCHMARK(BM_MassSpringDeformation)
    ->Arg(180)
    ->Arg(360)
    ->Arg(540)
    ->Arg(720)
    ->Unit(benchmark::kMicrosecond);

// A tool above the middle of the tube's top, 0.5 mm into it.
Eigen::Vector3d tool_over_middle(const MassSpringModel& body) {
  Eigen::Vector3d top = Eigen::Vector3d::Zero();
  const int section = body.section_count / 2;
  for (int k = 1; k <= kRingNodes; ++k) {
    const Eigen::Vector3d x = body.network.rest_positions.col(kSectionNodes * section + k);
    if (x.z() > top.z()) top = x;
  }
  return top + Eigen::Vector3d(0, 0, 0.0015);
}

void BM_MassSpringCollisionFaces(benchmark::State& state) {
  const MassSpringModel body = paper_body(static_cast<int>(state.range(0)) / kSectionNodes);
  const Eigen::Vector3d tool = tool_over_middle(body);
  for (auto _ : state)
    benchmark::DoNotOptimize(
        find_surface_contact(body.network, body.network.rest_positions, tool, 0.002));
}
BENCHMARK(BM_MassSpringCollisionFaces)
    ->Name("BM_MassSpringCollision/faces")
    ->Arg(180)
    ->Arg(360)
    ->Arg(540)
    ->Arg(720);

void BM_MassSpringCollisionAllTriangles(benchmark::State& state) {
  const MassSpringModel body = paper_body(static_cast<int>(state.range(0)) / kSectionNodes);
  const Eigen::Vector3d tool = tool_over_middle(body);
  const Eigen::Matrix3Xd& x = body.network.rest_positions;
  for (auto _ : state) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& t : body.network.triangles)
      nearest = std::min(
          nearest,
          (closest_point_on_triangle(tool, x.col(t[0]), x.col(t[1]), x.col(t[2])).point - tool)
              .squaredNorm());
    benchmark::DoNotOptimize(nearest);
  }
}
BENCHMARK(BM_MassSpringCollisionAllTriangles)
    ->Name("BM_MassSpringCollision/all_triangles")
    ->Arg(180)
    ->Arg(360)
    ->Arg(540)
    ->Arg(720);

void BM_MassSpringCriticalStep(benchmark::State& state) {
  const MassSpringModel body = paper_body(40, static_cast<double>(state.range(0)));
  double critical = 0;
  for (auto _ : state) benchmark::DoNotOptimize(critical = critical_time_step(body.network));
  state.counters["critical_ms"] = critical * 1e3;
}
BENCHMARK(BM_MassSpringCriticalStep)->Arg(9049)->Arg(1508)->Unit(benchmark::kMillisecond);

void BM_MassSpringClientTick(benchmark::State& state) {
  const MassSpringModel body = paper_body(40);
  const MassSpringState server = make_state(body.network);
  const Eigen::Vector3d tool = tool_over_middle(body) - Eigen::Vector3d(0, 0, 0.0005);
  IntermediateRepresentation ir;
  ir.tool_radius = 0.002;
  ir.force_limit = 3.3;
  MassSpringIr sub = build_mass_spring_ir(
      body, server, find_surface_contact(body.network, server.positions, tool, 0.002).nearest_node,
      static_cast<int>(state.range(0)));
  sub.presses.resize(1);
  const int nodes = sub.node_count();
  const std::size_t bytes = sub.size_bytes();
  ir.body = std::move(sub);
  const PreparedIR prepared = prepare_ir(std::move(ir));
  EvaluationState evaluation = make_evaluation_state(prepared);
  for (auto _ : state)
    benchmark::DoNotOptimize(evaluate_force(prepared, evaluation, tool, {}, 0.001).force.data());
  state.counters["nodes"] = nodes;
  state.counters["ir_bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_MassSpringClientTick)->Arg(1)->Arg(2)->Arg(4)->Arg(8)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace cohaptic
