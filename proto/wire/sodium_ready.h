// Makes sure libsodium is initialised before the wire layer uses it (random numbers,
// HMAC tags). Cheap after the first call: a function-local static.
#pragma once

namespace cohaptic::wire {

/// Calls sodium_init() once per process; throws cohaptic::Error if libsodium cannot start.
void ensure_sodium();

}  // namespace cohaptic::wire
