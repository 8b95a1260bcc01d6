// Condensation against independent answers: M~ forces equal the full sparse solve's
// reactions for random active sets, and the incremental path equals the naive one (which
// factors L_AA from scratch) to 1e-12 after thousands of random joins and leaves
// (including near incompressibility), after joins and leaves at the first, middle and
// last position of B, across contact-set changes that hit, miss and evict the cache of Z
// (with nodes that have only two free axes), and when the drift monitor refactors.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <random>
#include <string>

#include "common/condense/dof_blocks.h"
#include "common/condense/incremental_condensation.h"
#include "common/condense/naive_condensation.h"
#include "common/fem/static_solve.h"
#include "common/model/model.h"
#include "common/scene/load_scene.h"

namespace cohaptic {
namespace {

// The cube fixed at its rear face; with `sliding_side`, its x = -65 face also slides in
// its plane (x fixed), so that some surface nodes have two free dofs, not three.
Model cube_model(int divisions, double nu, bool sliding_side = false) {
  return build_model(parse_scene(
      fmt::format(
          R"(
units: mm
objects:
  - name: cube
    mesh: {{box: {{min: [-65, -65, -130], size: [130, 130, 130], divisions: [{0}, {0}, {0}]}}}}
    material: {{youngs_modulus: 1.0e6, poisson_ratio: {1}}}
    fixed: [{{plane: {{point: [0, 0, -130], normal: [0, 0, 1]}}}}{2}]
tools: [{{name: A}}]
)",
          divisions, nu,
          sliding_side ? ", {plane: {point: [-65, 0, 0], normal: [1, 0, 0]}, axes: x}" : ""),
      "cube.yaml"));
}

// Surface nodes that can move (not on the fixed rear face).
std::vector<int> movable_surface_nodes(const Model& model) {
  const ElasticBody& body = single_elastic_body(model);
  std::vector<int> nodes;
  for (int node : body.surface.nodes)
    if (body.dofs.fixed_axes[node] != kAllAxes) nodes.push_back(node);
  return nodes;
}

double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(b.norm(), 1e-300);
}

// The incremental M~ for `contact` equals the naive one to 1e-12; returns the larger
// relative difference of M_CC and M_CB.
double expect_equals_naive(IncrementalCondensation& incremental, ComplianceColumns& columns,
                           const DofMap& dofs, const std::vector<int>& contact,
                           const std::string& when) {
  const CondensedOperator fast = incremental.condense(contact);
  const CondensedOperator naive =
      naive_condensation(columns, dofs, contact, incremental.boundary_nodes());
  EXPECT_EQ(fast.contact_dofs, naive.contact_dofs) << when;
  EXPECT_EQ(fast.boundary_dofs, naive.boundary_dofs) << when;
  const double difference = std::max(relative_difference(fast.m_cc, naive.m_cc),
                                     relative_difference(fast.m_cb, naive.m_cb));
  EXPECT_LE(difference, 1e-12) << when << ", |B| " << incremental.boundary_nodes().size();
  return difference;
}

TEST(Condensation, ForcesEqualTheFullSparseSolveForRandomActiveSets) {
  const Model model = cube_model(8, 0.4);
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(body.free_factor, body.dofs, body.surface.nodes);
  const std::vector<int> candidates = movable_surface_nodes(model);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> displacement(-2e-3, 2e-3);
  for (int trial = 0; trial < 8; ++trial) {
    std::vector<int> shuffled = candidates;
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    const std::vector<int> contact(shuffled.begin(), shuffled.begin() + 3 + trial % 4);
    const std::vector<int> boundary(shuffled.begin() + 10, shuffled.begin() + 10 + 20 * trial);
    IncrementalCondensation incremental(columns, body.dofs);
    incremental.set_boundary_nodes(boundary);
    const CondensedOperator op = incremental.condense(contact);

    Eigen::VectorXd u_c(static_cast<Eigen::Index>(op.contact_dofs.size()));
    Eigen::VectorXd u_b(static_cast<Eigen::Index>(op.boundary_dofs.size()));
    std::vector<PrescribedDisplacement> prescribed;
    for (Eigen::Index i = 0; i < u_c.size(); ++i)
      prescribed.push_back({op.contact_dofs[i], u_c[i] = displacement(rng)});
    for (Eigen::Index i = 0; i < u_b.size(); ++i)
      prescribed.push_back({op.boundary_dofs[i], u_b[i] = displacement(rng)});
    const StaticSolution full = solve_static(body.stiffness, body.dofs, prescribed);

    const Eigen::VectorXd f_c = op.m_cc * u_c + op.m_cb * u_b;
    Eigen::VectorXd expected(f_c.size());
    for (Eigen::Index i = 0; i < f_c.size(); ++i) expected[i] = full.reaction[op.contact_dofs[i]];
    EXPECT_LE((f_c - expected).norm(), 1e-9 * expected.norm())
        << "trial " << trial << ", |B| " << boundary.size();
  }
}

void incremental_matches_naive_after_random_updates(double nu) {
  const Model model = cube_model(6, nu);
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(body.free_factor, body.dofs, body.surface.nodes);
  const std::vector<int> candidates = movable_surface_nodes(model);
  IncrementalCondensation incremental(columns, body.dofs);
  std::mt19937 rng(nu < 0.4 ? 17 : 29);
  std::vector<int> boundary;
  std::vector<int> contact;
  double worst = 0;
  const int operations = 10000;
  for (int op = 1; op <= operations; ++op) {
    // Drift around 40 nodes: join more often when small, leave more often when large.
    const bool join = boundary.empty() || std::uniform_int_distribution<int>(0, 79)(rng) >=
                                              static_cast<int>(boundary.size());
    if (join) {
      int node;
      do
        node =
            candidates[std::uniform_int_distribution<std::size_t>(0, candidates.size() - 1)(rng)];
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
        it = std::find(boundary.begin(), boundary.end(), *it) != boundary.end() ? contact.erase(it)
                                                                                : it + 1;
      if (contact.empty()) continue;
      worst = std::max(worst, expect_equals_naive(incremental, columns, body.dofs, contact,
                                                  fmt::format("after {} updates", op)));
      ASSERT_FALSE(::testing::Test::HasFailure());
    }
  }
  const auto& stats = incremental.statistics();
  std::printf(
      "  nu = %g: %ld joins, %ld leaves, %ld residual checks, %ld refactorisations, worst |dM|/|M| "
      "= %.2e\n",
      nu, stats.joins, stats.leaves, stats.residual_checks, stats.refactorizations, worst);
  EXPECT_EQ(stats.joins + stats.leaves, operations);
}

TEST(Condensation, IncrementalEqualsNaiveAfterTenThousandJoinsAndLeaves) {
  incremental_matches_naive_after_random_updates(0.3);
}

TEST(Condensation, IncrementalEqualsNaiveNearIncompressibility) {
  incremental_matches_naive_after_random_updates(0.499);
}

// A node leaves B from its first, a middle and its last position, and joins again (at the
// end); with the Z of the contact nodes cached before (corrected at each change) and not
// (computed afterwards from the factor alone). L_BB^-1 from the factor is checked against
// a dense factorisation of L_BB as well.
TEST(Condensation, JoinsAndLeavesAtTheFirstMiddleAndLastPositionEqualNaive) {
  for (double nu : {0.3, 0.499}) {
    const Model model = cube_model(6, nu, true);
    const ElasticBody& body = single_elastic_body(model);
    ComplianceColumns columns(body.free_factor, body.dofs, body.surface.nodes);
    const std::vector<int> candidates = movable_surface_nodes(model);
    std::vector<int> shuffled = candidates;
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(5));
    const std::vector<int> contact(shuffled.begin(), shuffled.begin() + 4);
    const std::vector<int> initial(shuffled.begin() + 4, shuffled.begin() + 34);
    for (bool cached : {true, false}) {
      IncrementalCondensation incremental(columns, body.dofs);
      for (int node : initial) incremental.add_boundary_node(node);  // one by one: bordering
      if (cached) expect_equals_naive(incremental, columns, body.dofs, contact, "before any leave");
      const std::size_t size = incremental.boundary_nodes().size();
      for (std::size_t position : {std::size_t{0}, size / 2, size - 1}) {
        const int node = incremental.boundary_nodes()[position];
        const std::string where =
            fmt::format("nu {}, cached {}, position {}", nu, cached, position);
        incremental.remove_boundary_node(node);
        if (cached) expect_equals_naive(incremental, columns, body.dofs, contact, where + " left");

        const std::vector<int> b_dofs = free_dofs_of_nodes(body.dofs, incremental.boundary_nodes());
        const Eigen::MatrixXd l_bb = gather_compliance(columns, b_dofs, b_dofs);
        const Eigen::MatrixXd rhs = Eigen::MatrixXd::Random(l_bb.rows(), 2);
        const Eigen::MatrixXd expected = l_bb.llt().solve(rhs);
        EXPECT_LE(relative_difference(incremental.solve_boundary(rhs), expected), 1e-12) << where;

        incremental.add_boundary_node(node);
        EXPECT_EQ(incremental.boundary_nodes().back(), node);
        expect_equals_naive(incremental, columns, body.dofs, contact, where + " joined again");
      }
    }
  }
}

// The contact set changes while B changes: new nodes (a cache miss), nodes seen before (a
// hit), more nodes than the cache keeps (it evicts, and later recomputes), nodes with two
// free axes (the sliding face) in both C and B.
TEST(Condensation, ContactSetChangesEqualNaive) {
  const Model model = cube_model(6, 0.45, true);
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(body.free_factor, body.dofs, body.surface.nodes);
  std::vector<int> candidates = movable_surface_nodes(model);
  std::vector<int> sliding;
  for (int node : candidates)
    if (body.dofs.fixed_axes[node] != 0) sliding.push_back(node);
  ASSERT_GE(sliding.size(), 10u);
  std::mt19937 rng(11);
  std::shuffle(candidates.begin(), candidates.end(), rng);
  IncrementalCondensation::Options options;
  options.z_cache_nodes = 5;
  IncrementalCondensation incremental(columns, body.dofs, options);
  std::vector<int> boundary = {sliding[0], sliding[1]};
  for (auto it = candidates.begin(); boundary.size() < 25; ++it)
    if (std::find(sliding.begin(), sliding.end(), *it) == sliding.end()) boundary.push_back(*it);
  incremental.set_boundary_nodes(boundary);  // more than a few at once: factored from scratch

  // Nodes for C: never in B.
  std::vector<int> pool = {sliding[2], sliding[3], sliding[4], sliding[5]};
  for (int node : candidates)
    if (pool.size() < 12 && std::find(boundary.begin(), boundary.end(), node) == boundary.end() &&
        std::find(sliding.begin(), sliding.end(), node) == sliding.end())
      pool.push_back(node);
  const std::vector<std::vector<int>> contacts = {
      {pool[0], pool[1], pool[4]},                             // all new
      {pool[1], pool[4], pool[5]},                             // two hits, one new
      {pool[2], pool[3], pool[6], pool[7], pool[8], pool[9]},  // more than the cache keeps
      {pool[0], pool[1], pool[4]},                             // evicted before: recomputed
      {pool[10], pool[11], pool[0]}};
  // Spare nodes that join and leave B between contact changes.
  std::vector<int> spare;
  for (int node : candidates)
    if (spare.size() < 6 && std::find(boundary.begin(), boundary.end(), node) == boundary.end() &&
        std::find(pool.begin(), pool.end(), node) == pool.end())
      spare.push_back(node);
  spare.push_back(sliding[6]);
  for (int round = 0; round < 3; ++round)
    for (std::size_t i = 0; i < contacts.size(); ++i) {
      expect_equals_naive(incremental, columns, body.dofs, contacts[i],
                          fmt::format("round {}, contact set {}", round, i));
      // One join and one leave from a random position before the next contact set.
      const int joining = spare[(round * contacts.size() + i) % spare.size()];
      if (incremental.in_boundary(joining))
        incremental.remove_boundary_node(joining);
      else
        incremental.add_boundary_node(joining);
      const auto& b = incremental.boundary_nodes();
      incremental.remove_boundary_node(
          b[std::uniform_int_distribution<std::size_t>(0, b.size() - 2)(rng)]);
      expect_equals_naive(incremental, columns, body.dofs, contacts[i],
                          fmt::format("round {}, after B changed", round));
    }
}

// A tolerance no residual meets: every check refactors, which must rebuild the factor and
// every cached Z exactly; so must a bulk join (many nodes at once, factored from scratch)
// while Z is cached, which gives every Z new rows.
TEST(Condensation, RefactoringKeepsTheCondensationExact) {
  const Model model = cube_model(5, 0.4);
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(body.free_factor, body.dofs, body.surface.nodes);
  const std::vector<int> candidates = movable_surface_nodes(model);
  IncrementalCondensation::Options options;
  options.drift_tolerance = -1;
  options.check_interval = 3;
  IncrementalCondensation incremental(columns, body.dofs, options);
  const std::vector<int> contact = {candidates[0], candidates[1], candidates[2]};
  std::mt19937 rng(7);
  for (int op = 0; op < 60; ++op) {
    const int node =
        candidates[std::uniform_int_distribution<std::size_t>(3, candidates.size() - 1)(rng)];
    if (incremental.in_boundary(node))
      incremental.remove_boundary_node(node);
    else
      incremental.add_boundary_node(node);
    if (op % 4 == 0)
      expect_equals_naive(incremental, columns, body.dofs, contact,
                          fmt::format("after {} updates", op));
  }
  EXPECT_EQ(incremental.statistics().refactorizations, incremental.statistics().residual_checks);
  EXPECT_GE(incremental.statistics().refactorizations, 15);

  std::vector<int> more = incremental.boundary_nodes();
  for (std::size_t i = 3;
       i < candidates.size() && more.size() < incremental.boundary_nodes().size() + 20; ++i)
    if (!incremental.in_boundary(candidates[i])) more.push_back(candidates[i]);
  incremental.set_boundary_nodes(more);
  expect_equals_naive(incremental, columns, body.dofs, contact, "after a bulk join");
}

TEST(Condensation, ANodeInBothSetsOrTwiceInBIsAClearError) {
  const Model model = cube_model(4, 0.4);
  const ElasticBody& body = single_elastic_body(model);
  ComplianceColumns columns(body.free_factor, body.dofs, body.surface.nodes);
  const std::vector<int> nodes = movable_surface_nodes(model);
  IncrementalCondensation incremental(columns, body.dofs);
  incremental.add_boundary_node(nodes[0]);
  EXPECT_THROW(incremental.add_boundary_node(nodes[0]), Error);
  EXPECT_THROW(incremental.remove_boundary_node(nodes[1]), Error);
  const std::vector<int> contact = {nodes[0], nodes[2]};
  EXPECT_THROW(incremental.condense(contact), Error);
  EXPECT_THROW(naive_condensation(columns, body.dofs, contact, incremental.boundary_nodes()),
               NumericalError);
}

}  // namespace
}  // namespace cohaptic
