// Limits every part of a session agrees on: the scene parser refuses a scene with more tools
// (so the server never admits more participants), an IR carries at most the others' tools,
// and the haptic loop sizes its fixed buffers by them (it allocates nothing while it runs).
// Includes nothing of the project's.
#pragma once

namespace cohaptic {

/// Users (tools) in one session, the local one included.
constexpr int kMaxUsers = 4;

}  // namespace cohaptic
