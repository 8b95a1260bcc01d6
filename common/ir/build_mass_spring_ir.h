// The mass–spring body's IR (mass_spring_ir.h), cut out of the server's whole network: the
// sections within `sections` of the contact node's on each side are free, one more section
// on each side is held (the rim: it moves at the server's velocity during the client's
// integration, standing in for the rest of the body), and the body's own held nodes stay
// held. When the range reaches an end of the body there is no rim on that side; when it
// covers the whole body, the IR is the whole network. Springs and triangles are those with
// every node inside, renumbered locally (ascending body node order). The tools' part of
// the IR (remote users, their radii, the presses) is the caller's. Units: SI.
#pragma once

#include "common/ir/mass_spring_ir.h"
#include "common/mass_spring/mass_spring_state.h"
#include "common/model/mass_spring_body.h"

namespace cohaptic {

/// The sub-network of `body` around `contact_node` at `state`, `sections` free sections
/// each side (>= 0). Throws Error for a node out of range.
MassSpringIr build_mass_spring_ir(const MassSpringModel& body, const MassSpringState& state, int contact_node,
                                  int sections);

}  // namespace cohaptic
