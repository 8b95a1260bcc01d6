// The force on a sphere tool under the sphere contact model, from a prepared IR
// (common/contact/sphere_contact.h): the evaluator's sphere case, per haptic tick.
//
// Every row node of the IR that the model can hold is a candidate of the sphere (own, or a
// remote one at its given position) with the least gap along the node's normal; its
// clearance is q = g + q0, with q0 from the IR; a row node a rigid obstacle holds (the IR's
// obstacle rows) has the obstacle's gap instead, along the obstacle's normal, and pushes
// back on no tool directly. Which of them touch and with what push is the
// unilateral problem over the IR's normal compliance W, solved from where the evaluator's
// last tick on the same IR left it (incremental_contact_solve.h; the first tick starts from
// the server's contacts). The force on the own tool is -sum lambda_i n_i over the nodes its
// sphere pushes: exactly the full FEM solve's, as long as every node that touches a sphere
// is a row node of the IR.
// Flags: kInContact when the own sphere holds a node at rest or pushes one; kOutsidePatch
// when it reaches a surface node outside the IR (the force then leaves that node out until
// the next IR); kContactUnresolved when the solve did not finish within the state's work
// budget (kSphereSolveWork a tick): the force is then zero, the haptic loop holds the last
// resolved force and counts the tick, and the next tick goes on from where this one
// stopped; kNonFinite (zero force) for a non-finite tool or a state that is not this IR's.
// noexcept, lock-free, allocation-free.
#pragma once

#include <Eigen/Core>
#include <span>

#include "common/ir/evaluate_force.h"

namespace cohaptic {

/// `envelope` holds the own tool's radius and the force limit; `ir` is its body, `prepared`
/// what prepare_ir derived from it; `state` (made for this IR by make_evaluation_state) is
/// read and advanced.
ForceSample evaluate_sphere_contact(const IntermediateRepresentation& envelope,
                                    const CondensedFemIr& ir, const PreparedFem& prepared,
                                    SphereContactState* state, const Eigen::Vector3d& own_tool,
                                    std::span<const Eigen::Vector3d> remote_tools) noexcept;

}  // namespace cohaptic
