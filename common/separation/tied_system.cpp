#include "common/separation/tied_system.h"

#include <fmt/format.h>

#include "common/fem/static_solve.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

void add_mapped(std::vector<Eigen::Triplet<double, int>>& triplets, const SparseMatrix& k,
                const std::vector<int>& node_map) {
  for (int col = 0; col < k.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(k, col); it; ++it)
      triplets.emplace_back(3 * node_map[it.row() / 3] + it.row() % 3,
                            3 * node_map[it.col() / 3] + it.col() % 3, it.value());
}

}  // namespace

TiedSystem tied_system(const SeparationBodies& bodies, const SeparationInterface& interface,
                       const std::vector<bool>& tied) {
  if (static_cast<int>(tied.size()) != interface.node_count())
    throw Error(fmt::format("tied system: {} tie flags for {} interface nodes", tied.size(),
                            interface.node_count()));
  const int base_count = bodies.base.mesh.node_count();
  const int pulled_count = bodies.pulled.mesh.node_count();
  TiedSystem system;
  system.pulled_to_merged.assign(static_cast<std::size_t>(pulled_count), -1);
  for (int k = 0; k < interface.node_count(); ++k)
    if (tied[k]) system.pulled_to_merged[interface.pulled_nodes[k]] = interface.base_nodes[k];
  int next = base_count;
  for (int& merged : system.pulled_to_merged)
    if (merged < 0) merged = next++;
  std::vector<int> base_to_merged(static_cast<std::size_t>(base_count));
  for (int n = 0; n < base_count; ++n) base_to_merged[n] = n;

  std::vector<Eigen::Triplet<double, int>> triplets;
  add_mapped(triplets, assemble_stiffness(bodies.base.mesh, bodies.base.material), base_to_merged);
  add_mapped(triplets, assemble_stiffness(bodies.pulled.mesh, bodies.pulled.material),
             system.pulled_to_merged);
  system.stiffness.resize(3 * next, 3 * next);
  system.stiffness.setFromTriplets(triplets.begin(), triplets.end());

  std::vector<AxisMask> fixed(bodies.base.fixed_axes);
  fixed.resize(static_cast<std::size_t>(next), 0);
  for (int n = 0; n < pulled_count; ++n)
    fixed[system.pulled_to_merged[n]] |= bodies.pulled.fixed_axes[n];
  system.dofs = make_dof_map(std::move(fixed));
  return system;
}

std::vector<Eigen::Vector3d> footprint_forces(const TiedSystem& system,
                                              const SeparationInterface& interface,
                                              std::span<const int> footprint,
                                              std::span<const Eigen::Vector3d> deltas) {
  std::vector<int> prescribed;
  for (int k : footprint)
    for (int axis = 0; axis < 3; ++axis)
      prescribed.push_back(3 * system.pulled_to_merged[interface.pulled_nodes[k]] + axis);
  const ConstrainedStaticSolver solver(system.stiffness, system.dofs, prescribed);
  std::vector<Eigen::Vector3d> forces;
  for (const Eigen::Vector3d& delta : deltas) {
    Eigen::VectorXd values(static_cast<Eigen::Index>(prescribed.size()));
    for (std::size_t i = 0; i < prescribed.size(); ++i)
      values[static_cast<Eigen::Index>(i)] = delta[prescribed[i] % 3];
    const StaticSolution solution = solver.solve(values);
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    for (int dof : prescribed) force[dof % 3] += solution.reaction[dof];
    forces.push_back(force);
  }
  return forces;
}

}  // namespace cohaptic
