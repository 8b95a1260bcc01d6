// What the client derives once per intermediate representation for the sphere contact
// model (common/contact/sphere_contact.h, the IR's SphereContactIr): which rows of the
// normal compliance W have no negative entry (their nodes need no check while no push is
// negative: incremental_contact_solve.h); the guard ring's corners that are not row nodes
// (a sphere reaching one has left what the IR describes); and the contact solve started
// from the server's contacts, W over them factored here, off the haptic thread, so that an
// evaluator's first tick on the IR only adjusts it.
//
// The evaluator's mutable side, SphereContactState, lives in its EvaluationState: the
// contact solve as the last tick left it, and this tick's clearances. Units: m, N.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "common/contact/incremental_contact_solve.h"
#include "common/ir/intermediate_representation.h"

namespace cohaptic {

/// Work budget of one tick's contact solve, in multiply-adds: about 0.3 ms on the slowest
/// machine the haptic loop is meant for. Past it the tick is unresolved
/// (evaluate_sphere_contact.h).
constexpr double kSphereSolveWork = 1.5e6;

struct PreparedSphereContact {
  std::vector<std::uint8_t> nonnegative_rows;  ///< per row node
  Eigen::Matrix3Xd outside_corners;  ///< guard triangle corners that are not row nodes [m]
  IncrementalContactSolve start;     ///< K = the IR's contacts, factored
};

/// One evaluator's state of a sphere IR: its contact solve and this tick's scratch.
struct SphereContactState {
  IncrementalContactSolve solve;
  Eigen::VectorXd clearance;  ///< per row node: this tick's q [m] (+inf: no sphere reaches it)
  std::vector<std::int8_t> holder;  ///< per row node: the sphere holding it (0 own, 1 + r remote
                                    ///< r), or -1 (none, or an obstacle)
  double work_budget = kSphereSolveWork;  ///< per tick; a test or an offline tool may lift it
};

/// Checks the sphere IR (sizes, finite values, unit or zero normals, a symmetric W with a
/// positive diagonal for every node it can hold, contacts W is positive definite over, a
/// sphere for every tool; Error naming what is wrong) and derives the above;
/// `tool_radius` is the own tool's [m] (the IR's envelope holds it). `condition_estimate`
/// receives that of W over the contacts (1 without any).
PreparedSphereContact prepare_sphere_contact(const CondensedFemIr& ir, double tool_radius,
                                             double& condition_estimate);

/// An evaluator's first state: the prepared start.
SphereContactState make_sphere_contact_state(const PreparedSphereContact& prepared, int row_nodes);

}  // namespace cohaptic
