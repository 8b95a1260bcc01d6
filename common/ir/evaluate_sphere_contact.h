// The force on a sphere tool under the sphere contact model, from a prepared IR
// (common/contact/sphere_contact.h): the evaluator's sphere case, per haptic tick.
//
// Every contact node of the IR is a candidate of the sphere nearest it (the own sphere and
// the remote ones at their given positions), whether inside it at rest or not: a node the
// deformation carries into a sphere is pushed too. Each candidate's clearance
// q = g + n . u0 comes from its rest position and the IR's free displacement u0; which of
// them touch and with what push is the unilateral problem (working_set_contact_solve.h),
// with the normal compliance A = N^T L~ N read from the IR's condensed compliance L~ (B
// held) only against the working set, warm started from the evaluator's last tick on the
// same IR (cold without a warm start). The force on the own tool is -sum lambda_i n_i over
// its candidates: exactly the full FEM solve's, as long as every node that touches a
// sphere is a contact node of the IR.
// Flags: kInContact when the own sphere holds a node at rest or pushes one; kOutsidePatch
// when it reaches a surface node outside the IR (the force then leaves that node out until
// the next IR); kContactUnresolved (zero force) when the working set outgrows
// kMaxSphereContacts nodes or the solve did not finish within its budget (a few hundred
// microseconds): the haptic loop holds its last force and counts the tick. noexcept,
// lock-free, allocation-free.
#pragma once

#include <Eigen/Core>
#include <span>

#include "common/ir/evaluate_force.h"

namespace cohaptic {

/// Work budget of one tick's contact solve, in multiply-adds.
constexpr double kSphereSolveWork = 5e5;

/// `envelope` holds the own tool's radius and the force limit; `ir` is its body, `prepared`
/// what prepare_ir derived from it; `warm_start` (may be null: a cold solve) is read and
/// replaced by this tick's active set.
ForceSample evaluate_sphere_contact(const IntermediateRepresentation& envelope, const CondensedFemIr& ir,
                                    const PreparedFem& prepared, SphereWarmStart* warm_start,
                                    const Eigen::Vector3d& own_tool,
                                    std::span<const Eigen::Vector3d> remote_tools) noexcept;

}  // namespace cohaptic
