// ContactReference: the full sparse solve's reaction forces on a model's tools under node
// translation, for many tool positions in a row (a recorded or scripted motion).
//
// For a fixed set of contact triangles the solve is linear in the prescribed node
// displacements, so the reference factors K with those nodes' dofs prescribed once per
// distinct set (CHOLMOD), solves one unit case per pressing tool and axis, and answers
// every later position with the same set exactly (to round-off) by superposition: the
// answer of contact_reactions_reference() with nothing held, at a fraction of the cost.
// With held nodes (obstacles, step delay) their displacements are prescribed too; the
// factorisation for the latest set of contact triangles and held nodes is kept, and each
// call solves once with the actual values. A held node under a tool is not held: the tool
// wins, as in the simulation (whose held set may be a step older than the tools).
// Units: m, N. Not thread-safe (the caches grow).
#pragma once

#include <Eigen/Core>
#include <map>
#include <memory>
#include <vector>

#include "common/fem/static_solve.h"
#include "common/model/static_contact.h"

namespace cohaptic {

class ContactReference {
 public:
  /// `body` must outlive the reference.
  explicit ContactReference(const ElasticBody& body);

  /// Force on each tool [N] (zero for a tool that presses nothing), with `held` nodes at
  /// their displacements (but those under a tool). Throws Error if two tools press
  /// triangles sharing a node.
  std::vector<Eigen::Vector3d> forces(const std::vector<PressedTool>& tools,
                                      const HeldNodes& held = {});

  /// Factorisations so far (contact sets, and contact-and-held sets).
  std::size_t factorisations() const { return factorisations_; }

 private:
  // Reactions at the pressing triangles' nodes (3 x 3 per tool, column-major per node)
  // for a unit displacement of each pressing tool and axis: 9m x 3m.
  struct ContactSet {
    std::vector<std::size_t> pressing;  // tool indices
    Eigen::MatrixXd nodal_per_displacement;
  };
  const ContactSet& contact_set(const std::vector<ContactQuery>& contacts);
  std::vector<Eigen::Vector3d> forces_with_held(const std::vector<ContactQuery>& contacts,
                                                const HeldNodes& held);

  const ElasticBody& body_;
  std::map<std::vector<int>, ContactSet> sets_;  // keyed by contact triangle per tool (-1: none)
  // The latest contact-and-held set: its key, prescribed dofs and factorisation.
  std::vector<int> held_key_;
  std::unique_ptr<ConstrainedStaticSolver> held_solver_;
  std::size_t factorisations_ = 0;
};

}  // namespace cohaptic
