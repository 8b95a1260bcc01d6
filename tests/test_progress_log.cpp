// The progress line of a long task: bar, share, time spent and time left.
#include <gtest/gtest.h>

#include "common/util/progress_log.h"

namespace cohaptic {
namespace {

TEST(ProgressLog, TheLineShowsTheShareDoneAndTheTimeLeftAtTheRateSinceTheTotalWasSet) {
  EXPECT_EQ(ProgressLog::line("compliance", 1, 4, 10, 10),
            "compliance [#####...............]  25 %, 10.0 s, about 30 s left");
  EXPECT_EQ(ProgressLog::line("compliance", 3, 4, 30, 30),
            "compliance [###############.....]  75 %, 30.0 s, about 10 s left");
  // A later phase's total (saving, after computing): its rate from when that total was set.
  EXPECT_EQ(ProgressLog::line("compliance", 1, 4, 16, 2),
            "compliance [#####...............]  25 %, 16.0 s, about 6 s left");
  // Nothing done yet, or all of it: no estimate; more than the total counts as all.
  EXPECT_EQ(ProgressLog::line("x", 0, 4, 2, 2), "x [....................]   0 %, 2.0 s");
  EXPECT_EQ(ProgressLog::line("x", 5, 4, 2, 2), "x [####################] 100 %, 2.0 s");
  EXPECT_EQ(ProgressLog::line("x", 1, 0, 2, 2), "x [....................]   0 %, 2.0 s");
}

// A part that reports only at its end (a factorisation) moves at the expected rate, never to
// its end; with no expected rate it shows nothing until it ends.
TEST(ProgressLog, APartThatReportsOnlyAtItsEndMovesAtTheExpectedRateShortOfItsEnd) {
  EXPECT_DOUBLE_EQ(ProgressLog::shown_done(40, 100, 10, 3), 70);
  EXPECT_DOUBLE_EQ(ProgressLog::shown_done(40, 100, 10, 20), 40 + 95);
  EXPECT_DOUBLE_EQ(ProgressLog::shown_done(40, 100, 0, 20), 40);
  EXPECT_DOUBLE_EQ(ProgressLog::shown_done(40, 0, 10, 20), 40) << "no part running";
  // Three seconds into a part of 60 at 10 per second, of a total of 100: 30 % done, about 7 s left.
  EXPECT_EQ(ProgressLog::line("c", ProgressLog::shown_done(0, 60, 10, 3), 100, 3, 3),
            "c [######..............]  30 %, 3.0 s, about 7 s left");
}

}  // namespace
}  // namespace cohaptic
