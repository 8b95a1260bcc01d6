// SeparationIr: the IR body of a separating-tissue object (the separation-forces paper's
// model): the whole separation patch (geometry, regions, the three fitted fields per node,
// crack flags, fracture and laser settings), the server's separated state at the IR's
// simulation time, and the user's instrument (its settings and its state: grasp, fibre,
// jaws) as the server's step left them. The client steps the instrument on its own copy of
// the state at the haptic rate (step_separation_tool, the server's function), so it
// predicts fracture and vaporisation itself, within this patch; the server stays
// authoritative: every new IR replaces the client's state with the server's.
// The patch is shared (immutable) between the IRs the server builds from one body.
// Units: m, m^2, N, J/m^2, W, s.
#pragma once

#include <memory>

#include "common/separation/separation_tool.h"

namespace cohaptic {

struct SeparationIr {
  std::shared_ptr<const SeparationPatch> patch;
  SeparationState state;
  SeparationToolSettings tool;
  SeparationToolState tool_state;

  /// Bytes of the content as sent.
  std::size_t size_bytes() const;
};

/// Throws Error naming the first inconsistency a hostile or buggy peer could send: sizes,
/// indices, regions, non-finite or out-of-range values, the state and the contact.
void validate_separation_ir(const SeparationIr& ir);

}  // namespace cohaptic
