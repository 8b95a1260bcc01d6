// The simulation's own solve of the state under the sphere contact model
// (common/contact/sphere_contact.h): every sphere and every rigid obstacle at once, with the
// boundary nodes B held.
//
// Its candidates are the nodes of the users' patches (those their IRs carry), every
// touchable node whose gap to a sphere is less than twice the deepest penetration of a
// pushed node (or of B's largest normal move): the nodes the deformation could carry into
// a sphere, and the obstacles' candidates (below). Each is pushed along the direction of its
// constraint, the sphere's or obstacle's with the least gap (node_constraint); their
// normal compliance W with B held (normal_compliance.h) gives the unilateral problem over
// the pushes, solved from the last solve's set and factor (incremental_contact_solve.h), so
// that a step whose contact set barely changes costs O(|K|^2), and a candidate well clear
// of everything costs nothing (its row of W has no negative entry). If a solve pushes deeper
// than the candidates allowed for, the wider band joins and the state is solved again.
//
// The obstacles' candidates are, in the same way, the surface nodes whose gap to their
// obstacle at rest is less than that band (plus kObstacleBandMargin): the nodes the deformation
// could carry onto it; their band is the widest so far, so that they join once. As long as
// no node beyond the bands reaches a sphere or an obstacle (the bands' assumption, which
// the tests check against the full solve), the answer is that of the problem over every
// node, whatever the path: the obstacle lets its nodes slide and releases them as the
// unilateral problem says, in one step or many. The IRs carry the obstacle candidates
// within kObstacleReach of their obstacle in the solved state (or pushed by it) and any the
// patches hold: the obstacle rows. An IR stands while it holds every obstacle contact (a
// candidate pushed, or within kObstacleJoin): the nodes between the two distances may come
// and go without a new one. Under on-demand
// compliance the first widening of the band solves the columns of every obstacle node it
// takes in, within that step.
//
// The nodal forces lambda n then give f_B and any node's displacement as for the other models
// (state_solve.h). A node a sphere pushes outside the patches makes the simulation widen
// that user's patch (Simulation::SphereContacts::settle). Units: m, N. Not
// thread-safe.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/condense/normal_compliance.h"
#include "common/contact/incremental_contact_solve.h"
#include "common/contact/sphere_contact.h"
#include "common/model/elastic_body.h"
#include "common/sim/state_solve.h"

namespace cohaptic {

class SphereStateSolve {
 public:
  /// An obstacle candidate this near its obstacle in the solved state is an obstacle
  /// contact: an IR must hold it as a row [m].
  static constexpr double kObstacleJoin = 0.5e-3;
  /// An obstacle candidate this near its obstacle in the solved state is an obstacle row: a
  /// new IR holds it, so that the IR stands until a node farther than this comes within
  /// kObstacleJoin [m].
  static constexpr double kObstacleReach = 0.75e-3;
  /// An obstacle node whose gap at rest is within the candidates' band plus this is a
  /// candidate: a margin for the nodes the deformation could carry onto the obstacle [m].
  static constexpr double kObstacleBandMargin = 1e-3;

  /// `body` and `columns` (whose rows include every touchable node, every node an obstacle
  /// may hold and every node B may hold) must outlive it. `obstacles`: per volume node, its
  /// obstacle constraint (obstacle_constraints.h), or empty for none.
  SphereStateSolve(const ElasticBody& body, ComplianceColumns& columns,
                   std::vector<SphereConstraint> obstacles = {});

  /// The state with `spheres` pressing, over the candidates `patch_nodes` (any order,
  /// repeats allowed; nodes in B or that the model cannot hold are left out), u_B over the
  /// free dofs of B in the condensation's order. contact_dofs are the free dofs of the
  /// pushed nodes (by spheres and by obstacles); tool_forces[t] is sphere t's force on the
  /// object. Throws NumericalError if the problem cannot be solved.
  StateSolution solve(IncrementalCondensation& condensation, std::span<const int> patch_nodes,
                      std::span<const SphereTool> spheres,
                      const Eigen::VectorXd& boundary_displacement);

  /// The normal compliance over the last solve's candidates.
  const NormalCompliance& normal_compliance() const { return normal_; }
  /// The slots of normal_compliance() the last solve pushes.
  std::span<const int> contact_slots() const { return contact_.members(); }
  /// The last solve's obstacle rows (above): candidates an obstacle holds (their slots push
  /// along its normal), ascending.
  std::span<const int> obstacle_rows() const { return obstacle_rows_; }
  /// The last solve's obstacle contacts (above), ascending: rows an IR must hold.
  std::span<const int> obstacle_contacts() const { return obstacle_contacts_; }
  /// Per volume node, its obstacle constraint as given (empty: no obstacles).
  std::span<const SphereConstraint> obstacle_constraints() const { return obstacle_; }
  /// How many nodes the obstacles push in the last solve.
  int obstacle_pushed() const { return obstacle_pushed_; }

 private:
  /// The candidates become `nodes`: members leaving the set, or taking a new direction,
  /// leave the contact solve first, and a change of W under the members refactors it.
  void set_candidates(const std::vector<int>& nodes, IncrementalCondensation& condensation,
                      const Eigen::VectorXd& boundary_displacement);
  /// The obstacle rows of the solved state.
  void find_obstacle_rows(std::span<const int> patch_nodes);

  const ElasticBody& body_;
  ComplianceColumns& columns_;
  std::vector<int> touchable_;  // the touchable triangles' nodes: all that spheres can push
  std::vector<SphereConstraint> obstacle_;  // per volume node (empty: no obstacles)
  std::vector<int> obstacle_nodes_;         // the nodes with an obstacle constraint, ascending
  Eigen::Matrix3Xd directions_;  // per volume node: its push's direction as of the last solve
  NormalCompliance normal_;
  IncrementalContactSolve contact_;
  /// The band of the candidates: twice the deepest penetration.
  static constexpr double kBandPerDepth = 2;

  double band_ = 0;            // [m], as of the last solve
  double obstacle_band_ = 0;   // [m], the widest band so far
  Eigen::VectorXd clearance_;  // per slot, this solve's q
  std::vector<int>
      tool_;  // per slot, the sphere holding it (-1: none, or an obstacle: then q is finite)
  std::vector<int> obstacle_rows_, obstacle_contacts_;
  int obstacle_pushed_ = 0;
};

}  // namespace cohaptic
