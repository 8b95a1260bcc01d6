// Benchmarks of the laparoscopy model. The paper's floor is a
// 500 Hz - 2 kHz haptic loop (0.5 - 2 ms per tick) and >= 30 Hz graphics (33 ms per frame).
//   HomeSpringTick/<radius mm>: one haptic tick (shaft collision through the patch's AABB
//     tree, nearest vertex, Eq. 8) against the patch size, beside _scan, the same tick
//     with the collision by a scan of every patch triangle (the naive way), and
//     HomeSpringIrTick, the tick as the client runs it (the patch as the IR's body, through
//     evaluate_force, with the force limit).
//   HomeSpringLoad: Eq. 8 alone for one vertex and its 1-ring.
//   PolynomialDeformation/<columns>, FfdDeformation/<columns>: one display frame of a
//     sheet of (columns + 1)^2 vertices; FFD beside _naive, Eq. 2's triple sum with the
//     Bernstein polynomials recomputed (binomials and powers) per vertex every frame.
//   DirectManipulation_eq7 and _eq6/<points>: the control displacement for one point by
//     the paper's shortcut and for several points by the least-squares solution.
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>

#include "common/ir/evaluate_force.h"
#include "common/laparoscopy/direct_manipulation.h"
#include "common/laparoscopy/extract_home_spring_patch.h"
#include "common/laparoscopy/home_spring_contact.h"
#include "common/laparoscopy/home_spring_force.h"
#include "common/laparoscopy/polynomial_deformation.h"
#include "support/tissue_sheet.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;

constexpr double kSpacing = 0.002;  // 2 mm triangles
const Vector3d kPivot(0.01, 0.02, 0.15);

const TriangleSurface& sheet(int columns) {
  static std::map<int, std::unique_ptr<TriangleSurface>> sheets;
  auto& slot = sheets[columns];
  if (!slot)
    slot =
        std::make_unique<TriangleSurface>(testing::equilateral_sheet(columns, columns, kSpacing));
  return *slot;
}

PreparedHomeSpringPatch patch_of_radius(double radius) {
  const TriangleSurface& surface = sheet(80);  // 16 cm square
  const VertexRings rings = vertex_rings(surface.triangles, surface.vertex_count());
  return prepare_home_spring_patch(extract_home_spring_patch(
      {surface.vertices, surface.triangles, rings}, Vector3d::Zero(), radius, {300, 100}, kPivot));
}

/// The tool circling 3 mm below the sheet's centre, a new point every tick.
Vector3d circling_tool(int tick) {
  const double angle = 1e-3 * (tick % 6283);
  return Vector3d(0.004 * std::cos(angle), 0.004 * std::sin(angle), -0.003);
}

void set_patch_counters(benchmark::State& state, const HomeSpringPatch& patch) {
  state.counters["patch_vertices"] = patch.vertex_count();
  state.counters["patch_triangles"] = patch.triangle_count();
}

void BM_HomeSpringTick(benchmark::State& state) {
  const PreparedHomeSpringPatch prepared =
      patch_of_radius(1e-3 * static_cast<double>(state.range(0)));
  int tick = 0;
  for (auto _ : state)
    benchmark::DoNotOptimize(evaluate_home_spring(prepared, circling_tool(tick++)));
  set_patch_counters(state, prepared.patch);
}
BENCHMARK(BM_HomeSpringTick)->Arg(5)->Arg(10)->Arg(20)->Arg(40)->Unit(benchmark::kMicrosecond);

/// The same tick as the client runs it: the patch as the IR's body, through evaluate_force.
void BM_HomeSpringIrTick(benchmark::State& state) {
  IntermediateRepresentation ir;
  ir.force_limit = 10;
  ir.body = patch_of_radius(1e-3 * static_cast<double>(state.range(0))).patch;
  const PreparedIR prepared = prepare_ir(std::move(ir));
  EvaluationState evaluation = make_evaluation_state(prepared);
  int tick = 0;
  for (auto _ : state)
    benchmark::DoNotOptimize(
        evaluate_force(prepared, evaluation, circling_tool(tick++), {}, 1.0 / 2000));
  set_patch_counters(state, std::get<HomeSpringPatch>(prepared.ir.body));
}
BENCHMARK(BM_HomeSpringIrTick)->Arg(5)->Arg(40)->Unit(benchmark::kMicrosecond);

/// The naive tick: every triangle tested for the shaft's crossing, then the same Eq. 8.
HomeSpringContact scan_tick(const HomeSpringPatch& patch, const Vector3d& tool) {
  HomeSpringContact contact;
  double best = 2;
  for (const Triangle& tri : patch.triangles) {
    const auto crossing = segment_triangle_crossing(
        patch.trocar_pivot, tool, patch.rest_positions.col(tri[0]),
        patch.rest_positions.col(tri[1]), patch.rest_positions.col(tri[2]));
    if (!crossing || crossing->t >= best) continue;
    best = crossing->t;
    contact.contact_point = patch.trocar_pivot + crossing->t * (tool - patch.trocar_pivot);
    contact.vertex = tri[0];
    for (const int v : tri)
      if ((patch.rest_positions.col(v) - contact.contact_point).squaredNorm() <
          (patch.rest_positions.col(contact.vertex) - contact.contact_point).squaredNorm())
        contact.vertex = v;
  }
  if (contact.vertex < 0) return contact;
  contact.touching = true;
  contact.displacement = tool - contact.contact_point;
  contact.force = -home_spring_load(patch, contact.vertex, contact.displacement);
  return contact;
}

void BM_HomeSpringTick_scan(benchmark::State& state) {
  const PreparedHomeSpringPatch prepared =
      patch_of_radius(1e-3 * static_cast<double>(state.range(0)));
  int tick = 0;
  for (auto _ : state) benchmark::DoNotOptimize(scan_tick(prepared.patch, circling_tool(tick++)));
  set_patch_counters(state, prepared.patch);
}
BENCHMARK(BM_HomeSpringTick_scan)->Arg(5)->Arg(10)->Arg(20)->Arg(40)->Unit(benchmark::kMicrosecond);

void BM_HomeSpringLoad(benchmark::State& state) {
  const PreparedHomeSpringPatch prepared = patch_of_radius(0.005);
  const int vertex = nearest_touchable_vertex(prepared.patch, Vector3d::Zero());
  int tick = 0;
  for (auto _ : state)
    benchmark::DoNotOptimize(
        home_spring_load(prepared.patch, vertex, circling_tool(tick++) - Vector3d(0, 0, 0.001)));
}
BENCHMARK(BM_HomeSpringLoad)->Unit(benchmark::kMicrosecond);

void set_vertex_counter(benchmark::State& state, const Eigen::Matrix3Xd& vertices) {
  state.counters["vertices"] = static_cast<double>(vertices.cols());
}

void BM_PolynomialDeformation(benchmark::State& state) {
  const Eigen::Matrix3Xd& rest = sheet(static_cast<int>(state.range(0))).vertices;
  Eigen::Matrix3Xd deformed(3, rest.cols());
  int tick = 0;
  for (auto _ : state) {
    const Vector3d tool = circling_tool(tick++);
    deform_polynomial(rest, {Vector3d(tool.x(), tool.y(), 0), tool, 0.02}, deformed);
    benchmark::DoNotOptimize(deformed.data());
  }
  set_vertex_counter(state, rest);
}
BENCHMARK(BM_PolynomialDeformation)->Arg(31)->Arg(100)->Arg(316)->Unit(benchmark::kMicrosecond);

BernsteinLattice sheet_lattice(const Eigen::Matrix3Xd& rest) {
  const Vector3d margin(1e-3, 1e-3, 0.02);
  return identity_lattice(rest.rowwise().minCoeff() - margin, rest.rowwise().maxCoeff() + margin);
}

/// A grasp at the centre pulled 1 cm up, by Eq. 7.
LatticeControl pulled_control(const BernsteinLattice& lattice) {
  return lattice.control +
         single_point_manipulation(lattice_basis(lattice, Vector3d::Zero()), Vector3d(0, 0, 0.01));
}

void BM_FfdDeformation(benchmark::State& state) {
  const Eigen::Matrix3Xd& rest = sheet(static_cast<int>(state.range(0))).vertices;
  const BernsteinLattice lattice = sheet_lattice(rest);
  const LatticeBinding binding = bind_to_lattice(lattice, rest);
  const LatticeControl control = pulled_control(lattice);
  Eigen::Matrix3Xd deformed(3, rest.cols());
  for (auto _ : state) {
    deform_ffd(binding, control, deformed);
    benchmark::DoNotOptimize(deformed.data());
  }
  set_vertex_counter(state, rest);
}
BENCHMARK(BM_FfdDeformation)->Arg(31)->Arg(100)->Arg(316)->Unit(benchmark::kMicrosecond);

double binomial3(int i) { return i == 0 || i == 3 ? 1 : 3; }

void BM_FfdDeformation_naive(benchmark::State& state) {
  const Eigen::Matrix3Xd& rest = sheet(static_cast<int>(state.range(0))).vertices;
  const BernsteinLattice lattice = sheet_lattice(rest);
  const LatticeControl control = pulled_control(lattice);
  Eigen::Matrix3Xd deformed(3, rest.cols());
  for (auto _ : state) {
    for (Eigen::Index v = 0; v < rest.cols(); ++v) {
      const Vector3d uvw = lattice_coordinates(lattice, rest.col(v));
      Vector3d q = Vector3d::Zero();
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
          for (int k = 0; k < 4; ++k) {
            const double b = binomial3(i) * std::pow(uvw[0], i) * std::pow(1 - uvw[0], 3 - i) *
                             binomial3(j) * std::pow(uvw[1], j) * std::pow(1 - uvw[1], 3 - j) *
                             binomial3(k) * std::pow(uvw[2], k) * std::pow(1 - uvw[2], 3 - k);
            q += b * control.col(i + 4 * j + 16 * k);
          }
      deformed.col(v) = q;
    }
    benchmark::DoNotOptimize(deformed.data());
  }
  set_vertex_counter(state, rest);
}
BENCHMARK(BM_FfdDeformation_naive)->Arg(31)->Arg(100)->Arg(316)->Unit(benchmark::kMicrosecond);

void BM_DirectManipulation_eq7(benchmark::State& state) {
  const BernsteinLattice lattice = sheet_lattice(sheet(31).vertices);
  const LatticeBasis basis = lattice_basis(lattice, Vector3d(0.001, 0.002, 0));
  for (auto _ : state)
    benchmark::DoNotOptimize(single_point_manipulation(basis, Vector3d(0, 0, 0.01)));
}
BENCHMARK(BM_DirectManipulation_eq7)->Unit(benchmark::kMicrosecond);

void BM_DirectManipulation_eq6(benchmark::State& state) {
  const Eigen::Matrix3Xd& rest = sheet(31).vertices;
  const BernsteinLattice lattice = sheet_lattice(rest);
  const auto m = static_cast<Eigen::Index>(state.range(0));
  Eigen::Matrix<double, kLatticeControlPoints, Eigen::Dynamic> bases(kLatticeControlPoints, m);
  Eigen::Matrix3Xd displacements = Eigen::Matrix3Xd::Zero(3, m);
  displacements(2, 0) = 0.01;  // the grasp pulled up, the others pinned
  for (Eigen::Index i = 0; i < m; ++i)
    bases.col(i) = lattice_basis(lattice, rest.col((i * 97) % rest.cols()));
  for (auto _ : state) benchmark::DoNotOptimize(least_squares_manipulation(bases, displacements));
}
BENCHMARK(BM_DirectManipulation_eq6)->Arg(1)->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace cohaptic
