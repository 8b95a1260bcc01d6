// The progress line of a long task: bar, share, time spent and time left.
#include <gtest/gtest.h>

#include "common/util/progress_log.h"

namespace cohaptic {
namespace {

TEST(ProgressLog, TheLineShowsTheShareDoneAndTheTimeLeftAtTheRateSoFar) {
  EXPECT_EQ(ProgressLog::line("compliance", 1, 4, 10), "compliance [#####...............]  25 %, 10.0 s, about 30 s left");
  EXPECT_EQ(ProgressLog::line("compliance", 3, 4, 30), "compliance [###############.....]  75 %, 30.0 s, about 10 s left");
  // Nothing done yet, or all of it: no estimate; more than the total counts as all.
  EXPECT_EQ(ProgressLog::line("x", 0, 4, 2), "x [....................]   0 %, 2.0 s");
  EXPECT_EQ(ProgressLog::line("x", 5, 4, 2), "x [####################] 100 %, 2.0 s");
  EXPECT_EQ(ProgressLog::line("x", 1, 0, 2), "x [....................]   0 %, 2.0 s");
}

}  // namespace
}  // namespace cohaptic
