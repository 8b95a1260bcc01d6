#include "client/timer_floors.h"

#include <pthread.h>
#include <sched.h>

#include <algorithm>

#include "client/cpu_steal.h"
#include "client/haptic_loop.h"

namespace cohaptic {
namespace {

bool pin_to_cpu(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(static_cast<std::size_t>(cpu), &set);
  return pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
}

std::int64_t steal_of(const std::vector<std::int64_t>& steal, int cpu) {
  return cpu >= 0 && static_cast<std::size_t>(cpu) < steal.size()
             ? steal[static_cast<std::size_t>(cpu)]
             : -1;
}

}  // namespace

nlohmann::json quantiles_us(const Histogram& period_ns) {
  return {{"p50", static_cast<double>(period_ns.quantile(0.5)) * 1e-3},
          {"p99", static_cast<double>(period_ns.quantile(0.99)) * 1e-3},
          {"max", static_cast<double>(period_ns.max()) * 1e-3}};
}

void TimerFloor::run(double rate_hz, const std::atomic<bool>& stop, bool realtime, int cpu) {
  pinned = cpu >= 0 && pin_to_cpu(cpu);
  if (realtime) enter_realtime(79);
  const HapticClock clock = HapticClock::monotonic();
  const auto period = static_cast<std::int64_t>(1e9 / rate_hz);
  std::int64_t deadline = clock.now_ns(clock.context) + period;
  std::int64_t last = 0;
  while (!stop.load(std::memory_order_relaxed)) {
    clock.sleep_until_ns(clock.context, deadline);
    const std::int64_t woke = clock.now_ns(clock.context);
    if (pinned && sched_getcpu() != cpu) ++wakes_off_cpu;
    if (last) period_ns.record(woke - last);
    last = woke;
    missed_deadlines += skip_missed_deadlines(deadline, woke, period);
    deadline += period;
  }
}

TimerFloors::TimerFloors() {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) == 0)
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
      if (CPU_ISSET(static_cast<std::size_t>(cpu), &allowed)) floors_.push_back(OnCpu{cpu});
  if (floors_.empty()) floors_.emplace_back();
}

TimerFloors::~TimerFloors() { stop(); }

void TimerFloors::start(double rate_hz, bool realtime) {
  stop_ = false;
  const std::vector<std::int64_t> steal = cpu_steal_ns();
  for (OnCpu& on : floors_) {
    on.steal_at_start_ns = steal_of(steal, on.cpu);
    threads_.emplace_back(
        [this, &on, rate_hz, realtime] { on.floor->run(rate_hz, stop_, realtime, on.cpu); });
  }
}

void TimerFloors::stop() {
  if (threads_.empty()) return;
  stop_ = true;
  for (std::thread& thread : threads_) thread.join();
  threads_.clear();
  const std::vector<std::int64_t> steal = cpu_steal_ns();
  for (OnCpu& on : floors_) on.steal_at_stop_ns = steal_of(steal, on.cpu);
}

double TimerFloors::period_p99_us() const {
  double worst = 0;
  for (const OnCpu& on : floors_)
    worst = std::max(worst, static_cast<double>(on.floor->period_ns.quantile(0.99)) * 1e-3);
  return worst;
}

nlohmann::json TimerFloors::report() const {
  nlohmann::json cpus = nlohmann::json::array();
  nlohmann::json worst = {{"period_us", {{"p50", 0.0}, {"p99", 0.0}, {"max", 0.0}}},
                          {"missed_deadlines", 0}};
  for (const OnCpu& on : floors_) {
    const TimerFloor& floor = *on.floor;
    nlohmann::json one = {{"cpu", on.cpu},
                          {"pinned", floor.pinned},
                          {"wakes_off_cpu", floor.wakes_off_cpu},
                          {"period_us", quantiles_us(floor.period_ns)},
                          {"missed_deadlines", floor.missed_deadlines}};
    if (on.steal_at_start_ns >= 0 && on.steal_at_stop_ns >= 0)
      one["host_steal_ms"] = static_cast<double>(on.steal_at_stop_ns - on.steal_at_start_ns) * 1e-6;
    for (const char* q : {"p50", "p99", "max"})
      worst["period_us"][q] =
          std::max(worst["period_us"][q].get<double>(), one["period_us"][q].get<double>());
    worst["missed_deadlines"] =
        std::max(worst["missed_deadlines"].get<std::uint64_t>(), floor.missed_deadlines);
    cpus.push_back(std::move(one));
  }
  worst["cpus"] = std::move(cpus);
  return worst;
}

}  // namespace cohaptic
