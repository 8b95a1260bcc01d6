// The incremental unilateral solve (incremental_contact_solve.h) against the dense solve of
// the same problem (unilateral_contact_solve.h, itself checked against an enumeration of
// every active set): from any kept set, along a long sequence of moving clearances, with
// candidates that lose their constraint, past its work budget, and with a matrix that is
// not positive definite. The factor it keeps by updates must stay the factor of W_KK.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "common/contact/incremental_contact_solve.h"
#include "common/contact/unilateral_contact_solve.h"

namespace cohaptic::incremental_contact_solve_test {

constexpr double kUnlimited = std::numeric_limits<double>::infinity();

// A normal compliance like a body's surface: m points on a 20 x 20 mm patch, each pushing
// the others less the farther they are (a positive definite Gaussian kernel, no negative
// entry), plus its own local compliance [m/N].
struct Problem {
  Eigen::Matrix2Xd points;
  Eigen::MatrixXd w;
  std::vector<std::uint8_t> nonnegative;
};

Problem surface_like(std::mt19937& random, int m) {
  std::uniform_real_distribution<double> coordinate(-10e-3, 10e-3);
  Problem problem;
  problem.points.resize(2, m);
  for (int i = 0; i < m; ++i)
    problem.points.col(i) = Eigen::Vector2d(coordinate(random), coordinate(random));
  problem.w.resize(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j)
      problem.w(i, j) =
          1e-4 * std::exp(-(problem.points.col(i) - problem.points.col(j)).squaredNorm() /
                          (2e-3 * 2e-3)) +
          (i == j ? 2e-4 : 0.0);
  problem.nonnegative.assign(static_cast<std::size_t>(m), 1);
  return problem;
}

// The clearances of a sphere-like indenter of 20 mm radius at `centre` over the patch,
// `depth` deep [m].
Eigen::VectorXd clearances(const Problem& problem, const Eigen::Vector2d& centre, double depth) {
  Eigen::VectorXd q(problem.points.cols());
  for (Eigen::Index i = 0; i < q.size(); ++i)
    q[i] = (problem.points.col(i) - centre).squaredNorm() / (2 * 20e-3) - depth;
  return q;
}

struct Dense {
  Eigen::VectorXd lambda;
  std::vector<std::uint8_t> active;
};

Dense dense_solve(const Eigen::MatrixXd& w, const Eigen::VectorXd& q) {
  const auto m = static_cast<int>(q.size());
  // A candidate without a constraint is left out of the dense problem.
  std::vector<int> kept;
  for (int i = 0; i < m; ++i)
    if (std::isfinite(q[i])) kept.push_back(i);
  const auto n = static_cast<Eigen::Index>(kept.size());
  Eigen::MatrixXd a(n, n);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    b[i] = q[kept[static_cast<std::size_t>(i)]];
    for (Eigen::Index j = 0; j < n; ++j)
      a(i, j) = w(kept[static_cast<std::size_t>(i)], kept[static_cast<std::size_t>(j)]);
  }
  std::vector<std::uint8_t> active(static_cast<std::size_t>(n), 0);
  Eigen::VectorXd lambda(n);
  Eigen::MatrixXd factor(n, n);
  std::vector<int> order(static_cast<std::size_t>(n));
  EXPECT_TRUE(solve_unilateral_contact(a, b, active, lambda, factor, order, kUnlimited).solved);
  Dense dense{Eigen::VectorXd::Zero(m), std::vector<std::uint8_t>(static_cast<std::size_t>(m), 0)};
  for (Eigen::Index i = 0; i < n; ++i) {
    dense.lambda[kept[static_cast<std::size_t>(i)]] = lambda[i];
    dense.active[static_cast<std::size_t>(kept[static_cast<std::size_t>(i)])] =
        active[static_cast<std::size_t>(i)];
  }
  return dense;
}

// The incremental solve's pushes per candidate, and the largest relative difference from
// the dense solve's (asserting the same set).
double compare(const IncrementalContactSolve& solve, const Dense& dense) {
  const auto m = static_cast<int>(dense.lambda.size());
  double scale = dense.lambda.cwiseAbs().maxCoeff(), worst = 0;
  for (int i = 0; i < m; ++i) {
    EXPECT_EQ(solve.in_set(i), dense.active[static_cast<std::size_t>(i)] != 0) << "candidate " << i;
    worst = std::max(worst, std::abs(solve.push(i) - dense.lambda[i]) / std::max(scale, 1e-300));
  }
  return worst;
}

TEST(IncrementalContactSolve, FromAnyKeptSetEqualsTheDenseSolve) {
  std::mt19937 random(11);
  double worst = 0;
  int solves = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int m = 20 + 7 * trial;
    const Problem problem = surface_like(random, m);
    std::uniform_real_distribution<double> offset(-3e-3, 3e-3), depth(0.2e-3, 2e-3);
    const Eigen::VectorXd q =
        clearances(problem, Eigen::Vector2d(offset(random), offset(random)), depth(random));
    const Dense dense = dense_solve(problem.w, q);
    for (int start = 0; start < 3; ++start) {
      IncrementalContactSolve solve(m);
      std::vector<int> set;  // empty, every candidate, or a random half
      for (int i = 0; i < m; ++i)
        if (start == 1 || (start == 2 && random() % 2)) set.push_back(i);
      ASSERT_TRUE(solve.start_from(problem.w, set));
      const UnilateralSolveResult result =
          solve.solve(problem.w, q, problem.nonnegative, kUnlimited);
      ASSERT_TRUE(result.solved);
      worst = std::max(worst, compare(solve, dense));
      ++solves;
    }
  }
  std::printf(
      "  %d solves of 20 to 433 candidates from three kinds of kept set: largest relative "
      "difference %.2e\n",
      solves, worst);
  EXPECT_LT(worst, 1e-9);
}

TEST(IncrementalContactSolve, AlongAMovingToolEveryAnswerIsTheDenseSolvesAndTheFactorStaysTrue) {
  std::mt19937 random(5);
  const int m = 600;
  Problem problem = surface_like(random, m);
  // A few rows with negative entries (a body that also lifts far nodes), kept positive
  // definite (each pair adds e (u_i - u_j)(u_i - u_j)^T): they are checked in full; the
  // answer must not depend on that.
  constexpr double kLift = 1e-5;
  for (int i = 0; i < m; i += 25) {
    int j = 0;  // the candidate farthest from i, whose kernel entry is next to nothing
    (problem.points.colwise() - problem.points.col(i)).colwise().squaredNorm().maxCoeff(&j);
    problem.w(i, i) += kLift;
    problem.w(j, j) += kLift;
    problem.w(i, j) -= kLift;
    problem.w(j, i) -= kLift;
    ASSERT_LT(problem.w(i, j), 0);
    problem.nonnegative[static_cast<std::size_t>(i)] =
        problem.nonnegative[static_cast<std::size_t>(j)] = 0;
  }
  IncrementalContactSolve solve(m);
  double worst = 0, most_work = 0;
  int largest_set = 0, changes = 0;
  std::vector<int> previous;
  for (int tick = 0; tick <= 2000; ++tick) {
    // Down 2 mm, then round a 4 mm circle twice at that depth, then up.
    const double t = tick / 2000.0;
    const double depth = 2e-3 * std::min({1.0, 4 * t, 4 * (1 - t)}) - 0.3e-3;
    const Eigen::Vector2d centre =
        4e-3 * Eigen::Vector2d(std::cos(4 * M_PI * t), std::sin(4 * M_PI * t));
    Eigen::VectorXd q = clearances(problem, centre, depth);
    if (tick % 7 == 0)
      q[tick % m] = std::numeric_limits<double>::infinity();  // a node no tool reaches now
    const UnilateralSolveResult result = solve.solve(problem.w, q, problem.nonnegative, kUnlimited);
    ASSERT_TRUE(result.solved) << "tick " << tick;
    most_work = std::max(most_work, result.work);
    if (tick % 50 == 0) worst = std::max(worst, compare(solve, dense_solve(problem.w, q)));
    std::vector<int> set(solve.members().begin(), solve.members().end());
    std::sort(set.begin(), set.end());
    std::vector<int> changed;
    std::set_symmetric_difference(set.begin(), set.end(), previous.begin(), previous.end(),
                                  std::back_inserter(changed));
    changes += static_cast<int>(changed.size());
    previous = set;
    largest_set = std::max(largest_set, static_cast<int>(set.size()));
  }
  // After thousands of updates, the kept factor still solves W_KK: its pushes equal a
  // fresh factor's for the same set and clearances.
  const Eigen::VectorXd q = clearances(problem, Eigen::Vector2d(1e-3, 0), 1.5e-3);
  ASSERT_TRUE(solve.solve(problem.w, q, problem.nonnegative, kUnlimited).solved);
  IncrementalContactSolve fresh(m);
  ASSERT_TRUE(fresh.start_from(problem.w, solve.members()));
  ASSERT_TRUE(fresh.solve(problem.w, q, problem.nonnegative, kUnlimited).solved);
  double drift = 0, scale = 0;
  for (int i = 0; i < m; ++i) {
    drift = std::max(drift, std::abs(solve.push(i) - fresh.push(i)));
    scale = std::max(scale, std::abs(fresh.push(i)));
  }
  std::printf(
      "  2001 ticks over %d candidates: up to %d in contact, %d joins and leaves, at most %.3g "
      "multiply-adds a "
      "tick; largest difference from the dense solve %.2e, from a fresh factor %.2e\n",
      m, largest_set, changes, most_work, worst, drift / scale);
  EXPECT_GT(largest_set, 150) << "the tool pressed too little to test anything";
  EXPECT_GT(changes, 500);
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(drift / scale, 1e-11);
}

TEST(IncrementalContactSolve, PastItsBudgetItStopsAndGoesOnFromThereNextTime) {
  std::mt19937 random(3);
  const int m = 300;
  const Problem problem = surface_like(random, m);
  const Eigen::VectorXd q = clearances(problem, Eigen::Vector2d::Zero(), 2e-3);
  const Dense dense = dense_solve(problem.w, q);
  IncrementalContactSolve solve(m);
  int calls = 0;
  for (; calls < 1000; ++calls) {
    const UnilateralSolveResult result = solve.solve(problem.w, q, problem.nonnegative, 2e4);
    const double k = static_cast<double>(solve.members().size()) + 1;
    EXPECT_LE(result.work, 2e4 + 3 * k * k + m * k)
        << "a call overran its budget by more than a pass and a change";
    if (result.solved) break;
  }
  std::printf("  %d in contact from nothing, 2e4 multiply-adds a call: solved at call %d\n",
              static_cast<int>(solve.members().size()), calls + 1);
  EXPECT_GT(calls, 1) << "the budget was never short";
  EXPECT_LT(calls, 1000);
  EXPECT_LT(compare(solve, dense), 1e-9);
}

TEST(IncrementalContactSolve, AMatrixThatIsNotPositiveDefiniteGivesNoAnswerAndAnEmptySet) {
  Eigen::MatrixXd w(3, 3);
  w << 1, 2, 0, 2, 1, 0, 0, 0, 1;  // eigenvalue -1
  const Eigen::VectorXd q = Eigen::Vector3d(-1, -1, 1);
  const std::vector<std::uint8_t> nonnegative(3, 1);
  IncrementalContactSolve solve(3);
  EXPECT_FALSE(solve.start_from(w, std::vector<int>{0, 1}));
  EXPECT_TRUE(solve.members().empty());
  const UnilateralSolveResult result = solve.solve(w, q, nonnegative, kUnlimited);
  EXPECT_FALSE(result.solved);
  EXPECT_TRUE(solve.members().empty());
  EXPECT_FALSE(solve.start_from(w, std::vector<int>{0, 0})) << "a candidate listed twice";
  EXPECT_FALSE(solve.start_from(w, std::vector<int>{3})) << "beyond the capacity";
}

}  // namespace cohaptic::incremental_contact_solve_test
