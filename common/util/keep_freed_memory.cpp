#include "common/util/keep_freed_memory.h"

#include <malloc.h>
#include <unistd.h>

#include <cstdlib>
#include <vector>

namespace cohaptic {

void keep_freed_memory(std::size_t prefault_bytes) {
  // Each call fails only for a value out of range; these are in range.
  mallopt(M_ARENA_MAX, 1);  // one heap: what one thread frees, the next IR's thread reuses
  // glibc's largest mmap threshold (HEAP_MAX_SIZE / 2 on 64-bit); setting it also stops the
  // threshold's own adjustment.
  mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
  mallopt(M_TRIM_THRESHOLD, -1);  // never trim: the top of the heap stays for the next IR
  // The pool, in blocks below the threshold (so from the heap), each page written once.
  constexpr std::size_t kBlock = std::size_t{1} << 20;
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  std::vector<void*> blocks;
  blocks.reserve(prefault_bytes / kBlock);
  for (std::size_t made = 0; made + kBlock <= prefault_bytes; made += kBlock) {
    auto* block = static_cast<volatile char*>(std::malloc(kBlock));
    if (!block) break;
    for (std::size_t at = 0; at < kBlock; at += page) block[at] = 0;
    blocks.push_back(const_cast<char*>(block));
  }
  for (void* block : blocks) std::free(block);
}

}  // namespace cohaptic
