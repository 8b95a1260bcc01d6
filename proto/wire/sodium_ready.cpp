#include "proto/wire/sodium_ready.h"

#include <sodium.h>

#include "common/util/error.h"

namespace cohaptic::wire {

void ensure_sodium() {
  static const bool ready = sodium_init() >= 0;
  if (!ready) throw cohaptic::Error("libsodium could not be initialised");
}

}  // namespace cohaptic::wire
