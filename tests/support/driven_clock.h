// A haptic-loop clock the test drives, so each tick happens at an exact time whatever the
// machine's load. A sleep returns at once with the time set to its deadline (or left where
// it is, if a stall already took it past), then calls `at` with the new time, so a stimulus
// (a confirmation arriving) happens at an exact time on the loop's thread. Units: ns.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>

#include "client/haptic_loop.h"

namespace cohaptic::testing {

struct DrivenClock {
  std::int64_t now = 1'000'000'000;  // [ns]
  std::function<void(std::int64_t now)> at;
  HapticClock haptic() {
    return {[](void* self) { return static_cast<DrivenClock*>(self)->now; },
            [](void* self, std::int64_t deadline_ns) {
              DrivenClock& clock = *static_cast<DrivenClock*>(self);
              clock.now = std::max(clock.now, deadline_ns);
              if (clock.at) clock.at(clock.now);
            },
            this};
  }
};

}  // namespace cohaptic::testing
