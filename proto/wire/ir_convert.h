// cohaptic::IntermediateRepresentation (common/ir) <-> wire::IntermediateRepresentation
// (messages.proto), field by field.
//
// The mass-spring body (MassSpringPatch), the home-spring body (HomeSpringPatch) and the
// separation body (SeparationPatch, separation_convert.h) go in
// double, field by field; their round trips are bit-exact.
// Matrices: M~ column-major in m_tilde_f64 or m_tilde_f32 and u_B in
// boundary_displacement_f64 or _f32, by ir.precision; the wire form has no precision
// field: it is f32 if either f32 field is non-empty, f64 otherwise (so an IR whose M~ and
// u_B are both empty always comes back as f64). Vectors are x, y, z per node.
// to_wire then from_wire is bit-exact for f64 and exact for values already rounded to
// float (as build_ir stores them with precision f32).
// from_wire validates everything a hostile or buggy peer could get wrong and throws
// cohaptic::Error naming the first problem; it never reads out of range.
// (vec3_convert.h and surface_mesh_message.h are included for convenience.)
#pragma once

#include "cohaptic/messages.pb.h"
#include "common/ir/intermediate_representation.h"
#include "proto/wire/surface_mesh_message.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic::wire {

/// Fills `out` (cleared first), e.g. control.mutable_ir().
void to_wire(const cohaptic::IntermediateRepresentation& ir, IntermediateRepresentation* out);
IntermediateRepresentation to_wire(const cohaptic::IntermediateRepresentation& ir);

/// Validated conversion; throws cohaptic::Error "intermediate representation: <problem>".
cohaptic::IntermediateRepresentation from_wire(const IntermediateRepresentation& ir);

}  // namespace cohaptic::wire
