// cohaptic::SeparationIr (common/ir/separation_ir.h) <-> wire::SeparationPatch
// (messages.proto, the IR body's field 27), field by field in double: the round trip is
// bit-exact. separation_from_wire checks sizes and reads every index through its checked
// conversion, then validate_separation_ir checks the rest; errors name the problem
// ("separation patch: ...").
#pragma once

#include "cohaptic/messages.pb.h"
#include "common/ir/separation_ir.h"

namespace cohaptic::wire {

void separation_to_wire(const cohaptic::SeparationIr& ir, SeparationPatch* out);

cohaptic::SeparationIr separation_from_wire(const SeparationPatch& w);

}  // namespace cohaptic::wire
