// The server raises its own priority (server/raise_priority.h) before it starts its threads:
// the nice value is the calling thread's, and the threads it starts inherit it; where it is
// not permitted nothing changes. Run on a thread of its own, so the test program's threads
// keep theirs.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cerrno>
#include <thread>

#include "server/raise_priority.h"

namespace cohaptic::raise_priority_test {

int own_nice() {
  errno = 0;
  return getpriority(PRIO_PROCESS, 0);
}

TEST(RaisePriority, TheCallingThreadAndThoseItStartsAfterwardsAndNoOther) {
  const int before = own_nice();
  bool raised = false;
  int raised_nice = 0, inherited_nice = 0;
  std::thread([&] {
    raised = raise_priority(kServerNice);
    raised_nice = own_nice();
    std::thread([&] { inherited_nice = own_nice(); }).join();
  }).join();
  if (raised) {
    EXPECT_EQ(raised_nice, kServerNice);
    EXPECT_EQ(inherited_nice, kServerNice);
  } else {
    std::printf("  not permitted here (not root, no CAP_SYS_NICE): nothing changed\n");
    EXPECT_EQ(raised_nice, before);
    EXPECT_EQ(inherited_nice, before);
  }
  EXPECT_EQ(own_nice(), before) << "the test's own thread was changed";
}

}  // namespace cohaptic::raise_priority_test
