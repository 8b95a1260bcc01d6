// Benchmarks of the backing a body behind a mass-spring network gives its nodes, one
// substep's evaluation (what the front body's integrator, server or client, runs every
// substep), at 8, 16 and 32 backed nodes all pressing, a third of them shallow enough to
// be released by their neighbours' pushes:
//   BM_NodeBackingSubstep/dense/<n>       the dense backing (node_backing.h): the
//                                         unilateral solve over B's normal compliance,
//                                         warm-started from the previous substep's set
//   BM_NodeBackingSubstep/dense_cold/<n>  the same from an empty set (a set that changed)
//   BM_NodeBackingSubstep/lumped/<n>      the lumped form, the naive way: one
//                                         spring per node, k_i the row sum of A^-1, no
//                                         coupling
// B's compliance decays with the distance between targets (an elastic half-space's 1/r).
#include <benchmark/benchmark.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "common/mass_spring/node_backing.h"

namespace cohaptic {
namespace {

struct BackedRow {
  NodeBacking backing;
  Eigen::Matrix3Xd positions, velocities;
  explicit BackedRow(int count)
      : positions(3, count), velocities(Eigen::Matrix3Xd::Zero(3, count)) {
    backing.compliance.resize(count, count);
    for (int i = 0; i < count; ++i)
      for (int j = 0; j < count; ++j) backing.compliance(i, j) = 1e-4 / (1 + std::abs(i - j));
    backing.compliance.diagonal().array() += 1e-8 / 3.7e-3;
    backing.offsets = Eigen::VectorXd::Zero(count);
    backing.damping = Eigen::VectorXd::Constant(count, 0.4);
    backing.targets = Eigen::VectorXd::Zero(3 * count);
    backing.normals = Eigen::VectorXd::Zero(3 * count);
    for (int i = 0; i < count; ++i) {
      backing.nodes.push_back(i);
      backing.targets[3 * i] = 0.01 * i;
      backing.normals[3 * i + 2] = 1;
      positions.col(i) = Eigen::Vector3d(0.01 * i, 0, i % 3 == 1 ? -0.1e-3 : -1e-3);
    }
  }
};

void BM_NodeBackingSubstep_dense(benchmark::State& state, bool warm) {
  const BackedRow row(static_cast<int>(state.range(0)));
  NodeBackingSolve solve;
  prepare_backing_solve(solve, row.backing);
  Eigen::Matrix3Xd forces = Eigen::Matrix3Xd::Zero(3, row.positions.cols());
  for (auto _ : state) {
    if (!warm) std::fill(solve.active.begin(), solve.active.end(), std::uint8_t{0});
    add_node_backing_forces(row.backing, solve, row.positions, row.velocities, forces);
    benchmark::DoNotOptimize(forces.data());
  }
  state.counters["in_contact"] = static_cast<double>((solve.pushes.array() > 0).count());
  state.counters["failures"] = static_cast<double>(solve.failures);
}

void BM_NodeBackingSubstep_lumped(benchmark::State& state) {
  const BackedRow row(static_cast<int>(state.range(0)));
  const NodeBacking& backing = row.backing;
  const Eigen::VectorXd stiffness = backing.compliance.inverse().rowwise().sum();
  Eigen::Matrix3Xd forces = Eigen::Matrix3Xd::Zero(3, row.positions.cols());
  for (auto _ : state) {
    for (std::size_t k = 0; k < backing.nodes.size(); ++k) {
      const auto i = static_cast<Eigen::Index>(k);
      const int node = backing.nodes[k];
      const Eigen::Vector3d normal = backing.normals.segment<3>(3 * i);
      const double gap = (row.positions.col(node) - backing.targets.segment<3>(3 * i)).dot(normal);
      if (!(gap < 0)) continue;
      const double push =
          -stiffness[i] * gap - backing.damping[i] * row.velocities.col(node).dot(normal);
      if (push > 0) forces.col(node) += push * normal;
    }
    benchmark::DoNotOptimize(forces.data());
  }
}

BENCHMARK_CAPTURE(BM_NodeBackingSubstep_dense, dense, true)
    ->Name("BM_NodeBackingSubstep/dense")
    ->Arg(8)
    ->Arg(16)
    ->Arg(32);
BENCHMARK_CAPTURE(BM_NodeBackingSubstep_dense, dense_cold, false)
    ->Name("BM_NodeBackingSubstep/dense_cold")
    ->Arg(8)
    ->Arg(16)
    ->Arg(32);
BENCHMARK(BM_NodeBackingSubstep_lumped)
    ->Name("BM_NodeBackingSubstep/lumped")
    ->Arg(8)
    ->Arg(16)
    ->Arg(32);

}  // namespace
}  // namespace cohaptic
