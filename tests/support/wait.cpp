#include "support/wait.h"

#include <algorithm>
#include <thread>

namespace cohaptic::testing {

::testing::AssertionResult wait_until(const std::function<bool()>& condition,
                                      const std::string& what, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  // Short first polls keep a condition that holds within a millisecond (a datagram on
  // loopback) fast; the longer later ones keep a costly condition (reading a recording)
  // from competing with the processes it watches.
  std::chrono::microseconds interval{200};
  for (;;) {
    if (condition()) return ::testing::AssertionSuccess();
    if (std::chrono::steady_clock::now() > deadline)
      return condition() ? ::testing::AssertionSuccess()
                         : ::testing::AssertionFailure()
                               << "timed out after "
                               << std::chrono::duration<double>(timeout).count()
                               << " s waiting for " << what;
    std::this_thread::sleep_for(interval);
    interval = std::min<std::chrono::microseconds>(2 * interval, std::chrono::milliseconds(20));
  }
}

}  // namespace cohaptic::testing
