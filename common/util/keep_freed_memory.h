// keep_freed_memory: makes glibc's malloc keep the memory the process frees for its next
// allocations, and faults a pool of it in up front. The server builds, encodes and frees IRs
// of megabytes many times a second, and a client inflates and prepares each one: a block
// that large would otherwise get an mmap of its own, faulted in page by page (under
// mlockall(MCL_FUTURE), faulted and zeroed whole at once) and unmapped on free, so that every
// IR paid for its pages afresh, in the kernel, on the CPUs the haptic loops share (a page
// fault costs microseconds, tens of them in some virtual machines). With this, every thread
// allocates from the one heap, blocks up to 32 MB come from it, it is never trimmed, and
// `prefault_bytes` of it are faulted in before the session starts: the IRs' buffers reuse
// pages that are already there. The cost: the resident size stays at its peak.
// Call once, early in main(), before any other thread starts. Never throws.
#pragma once

#include <cstddef>

namespace cohaptic {

/// What the server and the client fault in: the working set of IRs of a few MB each (their
/// wire forms, compressed and not, W whole, and the contact solves' factors).
inline constexpr std::size_t kPrefaultedHeapBytes = std::size_t{64} << 20;

void keep_freed_memory(std::size_t prefault_bytes = kPrefaultedHeapBytes);

}  // namespace cohaptic
