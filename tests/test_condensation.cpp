// Condensation against independent answers: M~ forces equal the full sparse solve's
// reactions for random active sets, and the incremental path equals the naive one after
// thousands of random joins and leaves, including near incompressibility.
#include <gtest/gtest.h>

#include <random>

#include "common/condense/dof_blocks.h"
#include "common/condense/incremental_condensation.h"
#include "common/condense/naive_condensation.h"
#include "common/fem/static_solve.h"
#include "common/model/model.h"
#include "common/scene/load_scene.h"

namespace cohaptic {
namespace {

Model cube_model(int divisions, double nu) {
  return build_model(parse_scene(fmt::format(R"(
units: mm
objects:
  - name: cube
    mesh: {{box: {{min: [-65, -65, -130], size: [130, 130, 130], divisions: [{0}, {0}, {0}]}}}}
    material: {{youngs_modulus: 1.0e6, poisson_ratio: {1}}}
    fixed: [{{plane: {{point: [0, 0, -130], normal: [0, 0, 1]}}}}]
tools: [{{name: A}}]
)",
                                                 divisions, nu),
                                     "cube.yaml"));
}

// Surface nodes that can move (not on the fixed rear face).
std::vector<int> movable_surface_nodes(const Model& model) {
  std::vector<int> nodes;
  for (int node : model.surface.nodes)
    if (model.dofs.fixed_axes[node] != kAllAxes) nodes.push_back(node);
  return nodes;
}

double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(b.norm(), 1e-300);
}

TEST(Condensation, ForcesEqualTheFullSparseSolveForRandomActiveSets) {
  const Model model = cube_model(8, 0.4);
  ComplianceColumns columns(*model.free_factor, model.dofs, model.surface.nodes);
  const std::vector<int> candidates = movable_surface_nodes(model);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> displacement(-2e-3, 2e-3);
  for (int trial = 0; trial < 8; ++trial) {
    std::vector<int> shuffled = candidates;
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    const std::vector<int> contact(shuffled.begin(), shuffled.begin() + 3 + trial % 4);
    const std::vector<int> boundary(shuffled.begin() + 10, shuffled.begin() + 10 + 20 * trial);
    IncrementalCondensation incremental(columns, model.dofs);
    incremental.set_boundary_nodes(boundary);
    const CondensedOperator op = incremental.condense(contact);

    Eigen::VectorXd u_c(static_cast<Eigen::Index>(op.contact_dofs.size()));
    Eigen::VectorXd u_b(static_cast<Eigen::Index>(op.boundary_dofs.size()));
    std::vector<PrescribedDisplacement> prescribed;
    for (Eigen::Index i = 0; i < u_c.size(); ++i) prescribed.push_back({op.contact_dofs[i], u_c[i] = displacement(rng)});
    for (Eigen::Index i = 0; i < u_b.size(); ++i) prescribed.push_back({op.boundary_dofs[i], u_b[i] = displacement(rng)});
    const StaticSolution full = solve_static(model.stiffness, model.dofs, prescribed);

    const Eigen::VectorXd f_c = op.m_cc * u_c + op.m_cb * u_b;
    Eigen::VectorXd expected(f_c.size());
    for (Eigen::Index i = 0; i < f_c.size(); ++i) expected[i] = full.reaction[op.contact_dofs[i]];
    EXPECT_LE((f_c - expected).norm(), 1e-9 * expected.norm()) << "trial " << trial << ", |B| " << boundary.size();
  }
}

void incremental_matches_naive_after_random_updates(double nu) {
  const Model model = cube_model(6, nu);
  ComplianceColumns columns(*model.free_factor, model.dofs, model.surface.nodes);
  const std::vector<int> candidates = movable_surface_nodes(model);
  IncrementalCondensation incremental(columns, model.dofs);
  std::mt19937 rng(nu < 0.4 ? 17 : 29);
  std::vector<int> boundary;
  std::vector<int> contact;
  double worst = 0;
  const int operations = 10000;
  for (int op = 1; op <= operations; ++op) {
    // Drift around 40 nodes: join more often when small, leave more often when large.
    const bool join = boundary.empty() || std::uniform_int_distribution<int>(0, 79)(rng) >= static_cast<int>(boundary.size());
    if (join) {
      int node;
      do node = candidates[std::uniform_int_distribution<std::size_t>(0, candidates.size() - 1)(rng)];
      while (std::find(boundary.begin(), boundary.end(), node) != boundary.end());
      incremental.add_boundary_node(node);
      boundary.push_back(node);
    } else {
      const auto index = std::uniform_int_distribution<std::size_t>(0, boundary.size() - 1)(rng);
      incremental.remove_boundary_node(boundary[index]);
      boundary.erase(boundary.begin() + static_cast<std::ptrdiff_t>(index));
    }
    if (op % 250 == 0 || op == operations) {
      // A fresh contact triangle's worth of nodes outside B, sometimes reusing the last ones.
      if (op % 500 == 0 || contact.empty()) {
        contact.clear();
        for (int node : candidates)
          if (std::find(boundary.begin(), boundary.end(), node) == boundary.end() &&
              std::uniform_int_distribution<int>(0, 9)(rng) == 0 && contact.size() < 3)
            contact.push_back(node);
      }
      for (auto it = contact.begin(); it != contact.end();)
        it = std::find(boundary.begin(), boundary.end(), *it) != boundary.end() ? contact.erase(it) : it + 1;
      if (contact.empty()) continue;
      const CondensedOperator fast = incremental.condense(contact);
      const CondensedOperator naive = naive_condensation(columns, model.dofs, contact, incremental.boundary_nodes());
      ASSERT_EQ(fast.boundary_dofs, naive.boundary_dofs);
      worst = std::max({worst, relative_difference(fast.m_cc, naive.m_cc), relative_difference(fast.m_cb, naive.m_cb)});
      ASSERT_LE(relative_difference(fast.m_cc, naive.m_cc), 1e-9) << "after " << op << " updates, |B| " << boundary.size();
      ASSERT_LE(relative_difference(fast.m_cb, naive.m_cb), 1e-9) << "after " << op << " updates, |B| " << boundary.size();
    }
  }
  const auto& stats = incremental.statistics();
  std::printf("  nu = %g: %ld joins, %ld leaves, %ld residual checks, %ld refactorisations, worst |dM|/|M| = %.2e\n",
              nu, stats.joins, stats.leaves, stats.residual_checks, stats.refactorizations, worst);
  EXPECT_EQ(stats.joins + stats.leaves, operations);
}

TEST(Condensation, IncrementalEqualsNaiveAfterTenThousandJoinsAndLeaves) {
  incremental_matches_naive_after_random_updates(0.3);
}

TEST(Condensation, IncrementalEqualsNaiveNearIncompressibility) { incremental_matches_naive_after_random_updates(0.499); }

TEST(Condensation, ANodeInBothSetsOrTwiceInBIsAClearError) {
  const Model model = cube_model(4, 0.4);
  ComplianceColumns columns(*model.free_factor, model.dofs, model.surface.nodes);
  const std::vector<int> nodes = movable_surface_nodes(model);
  IncrementalCondensation incremental(columns, model.dofs);
  incremental.add_boundary_node(nodes[0]);
  EXPECT_THROW(incremental.add_boundary_node(nodes[0]), Error);
  EXPECT_THROW(incremental.remove_boundary_node(nodes[1]), Error);
  const std::vector<int> contact = {nodes[0], nodes[2]};
  EXPECT_THROW(incremental.condense(contact), Error);
  EXPECT_THROW(naive_condensation(columns, model.dofs, contact, incremental.boundary_nodes()), NumericalError);
}

}  // namespace
}  // namespace cohaptic
