// Waiting in tests for something to happen, not for a time to pass. wait_until polls a
// condition until it holds or a generous timeout runs out, and on timeout fails saying what
// was awaited. The timeout is far above what an idle machine needs, so a loaded machine
// makes a test slower, never wrong; the sleeps left in the tests are stimuli (a device
// holding still, a stall injected), each said so where it stands.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <string>

namespace cohaptic::testing {

/// Long enough for a server to load a scene and a client to join while every core is busy.
inline constexpr std::chrono::milliseconds kPatience{30'000};

/// Polls `condition` (first at once, then at intervals growing from 0.2 ms to 20 ms) until
/// it is true: success, or after `timeout` a failure "timed out after T s waiting for
/// <what>". Use as ASSERT_TRUE(wait_until(...)) << details.
::testing::AssertionResult wait_until(const std::function<bool()>& condition,
                                      const std::string& what,
                                      std::chrono::milliseconds timeout = kPatience);

}  // namespace cohaptic::testing
