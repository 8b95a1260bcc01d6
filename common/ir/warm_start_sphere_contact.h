// warm_start_sphere_contact: moves a prepared sphere IR's start, the contact solve an
// evaluator's first tick goes on from, from the server's contacts to those of the tools where
// they are now. An IR reaches its client a build, an encoding and a transfer after the tools
// were where its contacts put them: pressing on, a sphere has pushed dozens more nodes by then,
// and each that joins costs the first tick O(|K|^2) of its work budget. The client warms the
// start on its network thread as the IR arrives (the tools' latest positions it knows), with
// a budget of kWarmStartWork, so the first tick adjusts a solve that is milliseconds old.
// Deterministic: the same IR and positions give the same start bit for bit (a replay warms
// it again from the recorded positions).
#pragma once

#include <Eigen/Core>
#include <span>

#include "common/ir/evaluate_force.h"
#include "common/ir/prepared_sphere_contact.h"

namespace cohaptic {

/// The warm start's work budget in multiply-adds: a hundred ticks' (off the haptic thread).
inline constexpr double kWarmStartWork = 100 * kSphereSolveWork;

/// Solves `prepared`'s sphere contact (a condensed FEM IR under the sphere model) for the own
/// tool at `own` and the remote ones at `remotes` (the IR's remotes order; NaN: unknown) from
/// its start, and makes the answer the start. Returns false, leaving `prepared` as it was,
/// for another body or model, a non-finite own position, or a solve that did not resolve.
bool warm_start_sphere_contact(PreparedIR& prepared, const Eigen::Vector3d& own,
                               std::span<const Eigen::Vector3d> remotes);

}  // namespace cohaptic
