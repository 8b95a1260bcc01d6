// The client's timer floors: one bare timer pinned to each CPU the process may run on (so a
// stall of any one CPU, such as a vCPU the host deschedules, shows in the floor the loop is
// judged against), the report's worst-CPU figures, and the host's steal time per CPU.
#include <gtest/gtest.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <thread>

#include "client/cpu_steal.h"
#include "client/timer_floors.h"

namespace cohaptic {
namespace {

std::vector<int> cpus_allowed() {
  cpu_set_t set;
  CPU_ZERO(&set);
  EXPECT_EQ(sched_getaffinity(0, sizeof set, &set), 0);
  std::vector<int> cpus;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(static_cast<std::size_t>(cpu), &set)) cpus.push_back(cpu);
  return cpus;
}

TEST(TimerFloors, RunsOneBareTimerPinnedToEachCpuThisProcessMayUse) {
  const std::vector<int> allowed = cpus_allowed();
  TimerFloors floors;
  ASSERT_EQ(floors.size(), allowed.size());
  floors.start(1000, false);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  floors.stop();
  const nlohmann::json report = floors.report();
  ASSERT_EQ(report["cpus"].size(), allowed.size());
  std::uint64_t most_missed = 0;
  double largest_p99 = 0, largest_max = 0;
  for (std::size_t i = 0; i < allowed.size(); ++i) {
    SCOPED_TRACE("CPU " + std::to_string(allowed[i]));
    EXPECT_EQ(floors.cpu(i), allowed[i]);
    EXPECT_TRUE(floors.floor(i).pinned);
    EXPECT_EQ(floors.floor(i).wakes_off_cpu, 0u) << "a floor woke on another CPU than its own";
    EXPECT_GT(floors.floor(i).period_ns.count(), 100u) << "it ran about 300 periods";
    const nlohmann::json& cpu = report["cpus"][i];
    EXPECT_EQ(cpu["cpu"].get<int>(), allowed[i]);
    EXPECT_EQ(cpu["missed_deadlines"].get<std::uint64_t>(), floors.floor(i).missed_deadlines);
    most_missed = std::max(most_missed, floors.floor(i).missed_deadlines);
    largest_p99 = std::max(largest_p99, cpu["period_us"]["p99"].get<double>());
    largest_max = std::max(largest_max, cpu["period_us"]["max"].get<double>());
  }
  // The figures the loop is judged against are the worst CPU's.
  EXPECT_EQ(report["missed_deadlines"].get<std::uint64_t>(), most_missed);
  EXPECT_EQ(report["period_us"]["p99"].get<double>(), largest_p99);
  EXPECT_EQ(report["period_us"]["max"].get<double>(), largest_max);
  EXPECT_EQ(floors.period_p99_us(), largest_p99) << "the status reports what the report does";
  EXPECT_GE(largest_p99, 1000 - 1) << "a period is at least the 1 ms asked for";
}

// /proc/stat's steal column: one figure per CPU the kernel knows, never decreasing, a whole
// number of the kernel's clock ticks.
TEST(CpuSteal, GivesEachCpuItsStealTimeInWholeClockTicks) {
  const std::vector<std::int64_t> before = cpu_steal_ns();
  if (before.empty()) GTEST_SKIP() << "no /proc/stat";
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const std::vector<std::int64_t> after = cpu_steal_ns();
  const auto configured = static_cast<std::size_t>(sysconf(_SC_NPROCESSORS_CONF));
  EXPECT_GE(before.size(), std::min<std::size_t>(configured, cpus_allowed().back() + 1u));
  ASSERT_EQ(after.size(), before.size());
  const std::int64_t tick_ns = 1'000'000'000 / sysconf(_SC_CLK_TCK);
  for (int cpu : cpus_allowed()) {
    const auto i = static_cast<std::size_t>(cpu);
    EXPECT_GE(before[i], 0) << "CPU " << cpu << " has a steal figure";
    EXPECT_GE(after[i], before[i]) << "CPU " << cpu;
    EXPECT_EQ(before[i] % tick_ns, 0) << "CPU " << cpu;
  }
}

}  // namespace
}  // namespace cohaptic
