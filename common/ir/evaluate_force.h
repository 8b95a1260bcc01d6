// The force evaluator: the reaction force on a user's tool from an intermediate
// representation, its own tool position and the other users' tool positions.
//
// The same function serves the client's haptic loop (P1) and the server (P0). It is
// noexcept, takes no lock and allocates nothing: all working storage has a fixed maximum
// size (kMaxUsers users, each contributing at most 3 contact nodes), and what a dynamic
// body changes from tick to tick lives in the caller's EvaluationState, made with the
// prepared IR (make_evaluation_state) and advanced by dt, the loop's nominal period (or the
// time measured since the last call, evaluation_measures_elapsed_time), at every call. The
// condensed FEM body is static: it ignores dt, and its state is at most the sphere contact model's
// warm start. The mass-spring body (mass_spring_evaluation.h) integrates its sub-network over dt.
// The home-spring body is static too (its grasp travels in the IR) unless it is viscous:
// home_spring_contact.h's tick, from the shaft through the patch's trocar pivot, with a damping the
// vertex the tool holds or let go of moving over dt (viscous_home_spring.h); the sample's depth is
// then |u|, the contact vertex's displacement, and its triangle -1. The separation body
// (separation_ir.h) steps the user's instrument on the state that make_evaluation_state copied from
// the IR: grasp, fracture and the laser (its buttons), exactly as the server's step does; depth is
// then the deflection's length.
//
// The condensed FEM body:
// prepare_ir() runs once per IR, off the haptic thread: it checks the IR and inverts the
// contact block of M~ (in double) to the condensed compliance L~ = M_CC^-1 of the contact
// nodes with B held, and u0 = -L~ (M_CB u_B + f_rest), their displacement when they carry
// no force (f_rest: the IR's rest forces, zero unless the body carries other loads).
// Per tick the evaluator then:
//   1. finds the patch triangle nearest the own tool and whether it presses: signed
//      distance below the tool radius, the sign from the whole surface's pseudo-normals
//      at the patch and from the guard ring of triangles around it;
//   2. does the same for every remote tool against its contact triangle;
//   3. with Z the nodes of the pressing tools' triangles (all other contact nodes unloaded):
//      node translation: u_Z = d per tool, f_Z = L~_ZZ^-1 (u_Z - u0_Z), F = sum w_i f_i;
//      point constraint: f_Z = W lambda with W^T u_Z = d, (W^T L~_ZZ W) lambda = d - W^T u0_Z,
//      F = lambda (a 3x3 system per pressing user);
//   4. returns -F, set to zero if not finite and scaled down to the IR's force limit.
// Exactly the full FEM solve's answer for the same tool positions, as long as every tool
// stays on its IR triangles (the own tool within its patch).
// Under the sphere contact model the IR carries the normal compliance of its row nodes
// instead of M~, prepare_ir checks it and factors it over the server's contacts, and the
// evaluator solves the unilateral problem over every node the spheres reach
// (evaluate_sphere_contact.h), keeping its solve in the EvaluationState.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <span>
#include <variant>
#include <vector>

#include "common/ir/contact_solve.h"
#include "common/ir/intermediate_representation.h"
#include "common/ir/mass_spring_evaluation.h"
#include "common/ir/prepared_sphere_contact.h"
#include "common/kinds/body_kinds.h"
#include "common/laparoscopy/home_spring_contact.h"
#include "common/laparoscopy/viscous_home_spring.h"

namespace cohaptic {

/// What prepare_ir derives from a CondensedFemIr.
struct PreparedFem {
  Eigen::MatrixXd
      compliance;  ///< L~ over the free dofs of the contact nodes [m/N] (not for spheres)
  Eigen::VectorXd free_displacement;  ///< u0 over the same dofs [m] (not for spheres)
  std::vector<std::array<int, 3>>
      dof_index;                      ///< per contact node and axis: row in L~, or -1 if fixed
  std::vector<bool> on_patch_border;  ///< per patch node
  PreparedSphereContact sphere;       ///< the sphere contact model's (evaluate_sphere_contact.h)
};

/// The separation body needs nothing derived: prepare_ir validates it.
struct PreparedSeparation {};

/// What prepare_ir derives from an IR body: one alternative per body kind
/// (common/kinds/body_kinds.h), the IR body's own.
using PreparedBody =
    PerKind<ForKind<LinearElasticKind, PreparedFem>, ForKind<MassSpringKind, PreparedMassSpring>,
            ForKind<HomeSpringKind, PreparedHomeSpringPatch>,
            ForKind<SeparationKind, PreparedSeparation>>::variant;

/// An IR and what its evaluation needs, computed once: `body` holds the alternative that
/// matches ir.body's kind (PreparedFem for CondensedFemIr, PreparedMassSpring for
/// MassSpringIr, PreparedHomeSpringPatch for HomeSpringPatch, PreparedSeparation for
/// SeparationIr).
struct PreparedIR {
  IntermediateRepresentation ir;
  PreparedBody body;
  double condition_estimate = 1;  ///< of the body's operator (L~ for FEM)
};

/// Checks sizes, finiteness, symmetry (to 1e-9 of the largest entry) and positive
/// definiteness of M_CC; throws Error naming the problem.
PreparedIR prepare_ir(IntermediateRepresentation ir);

/// An FEM body's evaluator: under the sphere contact model its contact solve (warm-started
/// from tick to tick), under the paper's two models nothing (the body is static).
struct FemEvaluation {
  std::optional<SphereContactState> sphere;
};

/// A home-spring body's evaluator: the vertex that moves (its grasp travels in the IR). Only a
/// viscous body's (damping > 0) carries from tick to tick; it starts at rest.
struct HomeSpringEvaluation {
  bool viscous = false;
  bool started = false;  ///< evaluated at least once: evaluate_force_in_turn carries nothing in
  MovingVertex moving;
};

/// A separation body's evaluator: the separated state and the instrument, stepped per tick.
struct SeparationEvaluation {
  SeparationState state;
  SeparationToolState tool;
};

/// The mutable side of one evaluator of one prepared IR: one alternative per body kind
/// (common/kinds/body_kinds.h), the IR body's own (a mass-spring body's is its sub-network's
/// state). Made off the haptic thread, sized there.
using EvaluationBody = PerKind<ForKind<LinearElasticKind, FemEvaluation>,
                               ForKind<MassSpringKind, MassSpringPatchState>,
                               ForKind<HomeSpringKind, HomeSpringEvaluation>,
                               ForKind<SeparationKind, SeparationEvaluation>>::variant;

struct EvaluationState {
  EvaluationBody body;
};

/// The state an evaluator of `prepared` starts from (the server's state at the IR's time).
EvaluationState make_evaluation_state(const PreparedIR& prepared);

/// What an evaluator hands on to the evaluator of the user's next IR of the same body
/// (evaluate_force_in_turn): a
/// viscous tissue's moving vertex (viscous_home_spring.h), named by its surface index so the
/// previous IR need not outlive it. Small and copied; nothing for the other kinds.
struct EvaluationCarry {
  int object = -1;  ///< the scene object it was taken on; -1: nothing to carry
  MovingVertex moving;
};

/// Whether evaluating moves the body itself: a mass-spring sub-network or a separation steps
/// with every call, so a second evaluation in the same tick would step it twice, and so does a
/// viscous home-spring body's vertex. An FEM or elastic home-spring body is static (a sphere
/// contact solve is the evaluator's, not the body's).
bool evaluation_moves_the_body(const EvaluationState& state);

/// Whether the evaluator's dt should be the time measured since its previous evaluation
/// rather than the loop's nominal period: a viscous home-spring body's force is the vertex's
/// velocity, and a tick that comes late must not read as a fast tool. The other bodies step
/// by the nominal period (an integrator's step, kept stable).
bool evaluation_measures_elapsed_time(const EvaluationState& state);

enum ForceFlag : std::uint8_t {
  kInContact = 1,        ///< the own tool presses the surface
  kClamped = 2,          ///< scaled down to the force limit
  kNonFinite = 4,        ///< a non-finite input or result: force set to zero
  kOutsidePatch = 8,     ///< the tool is past the patch border: held on it until the next IR
  kRemoteOverlap = 16,   ///< a remote triangle shares a node with the own one or an earlier
                         ///< remote's: that remote ignored
  kTooManyRemotes = 32,  ///< remotes beyond kMaxUsers - 1 ignored
  kContactUnresolved =
      64,  ///< sphere model: the contact solve did not finish in its budget (zero force)
};

struct ForceSample {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< reaction on the own tool [N]
  int triangle = -1;                                ///< patch triangle nearest the tool
  double depth = 0;                                 ///< penetration below that triangle's plane [m]
  std::uint8_t flags = 0;
};

/// Never a non-finite or unbounded force: sets sample.force to zero (flagged kNonFinite) if
/// not `evaluated` or not finite, scales it down to `force_limit` (flagged kClamped) if above.
void limit_force(ForceSample& sample, bool evaluated, double force_limit) noexcept;

/// Dispatches on the body kind (a condensed FEM body under the sphere contact model is
/// evaluate_sphere_contact()). remote_tools[i] is the position of the tool of the body's
/// i-th remote contact [m] (NaN: unknown, ignored). `state` must come from
/// make_evaluation_state(prepared) and be advanced by no other IR; dt [s] is the period
/// since the previous call (the haptic loop's nominal period, or the measured time where
/// evaluation_measures_elapsed_time says so). A state of another kind
/// than the body's gives a zero force flagged kNonFinite. `buttons` are the own tool's
/// (bit i = button i held); only the separation body reads them.
ForceSample evaluate_force(const PreparedIR& prepared, EvaluationState& state,
                           const Eigen::Vector3d& own_tool,
                           std::span<const Eigen::Vector3d> remote_tools, double dt,
                           std::uint32_t buttons = 0) noexcept;

/// evaluate_force for a caller that evaluates one user's IRs in turn (the haptic loop, a
/// replay, the server's P0): a `state` not evaluated yet first goes on from `carry` if that
/// was taken on the same object, and `carry` becomes what `state` hands on to the next IR's.
ForceSample evaluate_force_in_turn(const PreparedIR& prepared, EvaluationState& state,
                                   EvaluationCarry& carry, const Eigen::Vector3d& own_tool,
                                   std::span<const Eigen::Vector3d> remote_tools, double dt,
                                   std::uint32_t buttons = 0) noexcept;

}  // namespace cohaptic
