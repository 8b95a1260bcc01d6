// COHAPTIC_SANITIZER_OWNS_MALLOC: defined when this translation unit is built with ASan or
// TSan. Their runtimes replace malloc, free and operator new with their own checked ones; a
// test that replaces them too (to count the haptic path's allocations) would hand glibc's
// blocks to the sanitizer's free, or the sanitizer's to glibc's, and abort the program at
// start-up. Such tests define their counters only without it and skip in sanitizer builds:
// the plain build counts.
#pragma once

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define COHAPTIC_SANITIZER_OWNS_MALLOC 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define COHAPTIC_SANITIZER_OWNS_MALLOC 1
#endif
#endif
