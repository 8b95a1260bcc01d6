// The simulation's own solve of the state under the sphere contact model
// (common/contact/sphere_contact.h): every sphere at once with the boundary nodes B held.
//
// Its candidates are the nodes of the users' patches (those their IRs carry) and every
// touchable node whose gap to a sphere is less than twice the deepest penetration of a
// pushed node (or of B's largest normal move): the nodes the deformation could carry into
// a sphere. Each is pushed along its own normal by the sphere with the least gap; their
// normal compliance W with B held (normal_compliance.h) gives the unilateral problem over
// the normal pushes, solved from the last solve's set and factor
// (incremental_contact_solve.h), so that a step whose contact set barely changes costs
// O(|K|^2), and a candidate well outside a sphere costs nothing (its row of W has no
// negative entry). If a solve pushes deeper than the candidates allowed for, the wider band
// joins and the state is solved again. The nodal forces lambda n then give f_B and any
// node's displacement as for the other models (state_solve.h). A pushed node outside the
// patches makes the simulation widen that user's patch
// (Simulation::carry_pushed_nodes_into_patches). Units: m, N. Not thread-safe.
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
  /// `body` and `columns` (whose rows include every touchable node and every node B may
  /// hold) must outlive it.
  SphereStateSolve(const ElasticBody& body, ComplianceColumns& columns);

  /// The state with `spheres` pressing, over the candidates `patch_nodes` (any order,
  /// repeats allowed; nodes in B or that the model cannot hold are left out), u_B over the
  /// free dofs of B in the condensation's order. contact_dofs are the free dofs of the
  /// pushed nodes; tool_forces[t] is sphere t's force on the object. Throws NumericalError if
  /// the problem cannot be solved.
  StateSolution solve(IncrementalCondensation& condensation, std::span<const int> patch_nodes,
                      std::span<const SphereTool> spheres, const Eigen::VectorXd& boundary_displacement);

  /// The normal compliance over the last solve's candidates.
  const NormalCompliance& normal_compliance() const { return normal_; }
  /// The slots of normal_compliance() the last solve pushes.
  std::span<const int> contact_slots() const { return contact_.members(); }

 private:
  /// The candidates become `nodes`: members leaving the set leave the contact solve first,
  /// and a change of W under the members refactors it.
  void set_candidates(const std::vector<int>& nodes, IncrementalCondensation& condensation,
                      const Eigen::VectorXd& boundary_displacement);

  const ElasticBody& body_;
  ComplianceColumns& columns_;
  std::vector<int> touchable_;  // the touchable triangles' nodes: all that can be pushed
  NormalCompliance normal_;
  IncrementalContactSolve contact_;
  /// The band of the candidates: twice the deepest penetration.
  static constexpr double kBandPerDepth = 2;

  double band_ = 0;             // [m], as of the last solve
  Eigen::VectorXd clearance_;   // per slot, this solve's q
  std::vector<int> tool_;       // per slot, the sphere with the least gap (-1: none)
};

}  // namespace cohaptic
