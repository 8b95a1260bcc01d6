// TimerFloors: the bare timer the haptic loop is judged against, once on every CPU the
// client may run on. A floor is a thread that does nothing but sleep to absolute deadlines
// at the loop's rate (SCHED_FIFO just below the haptic thread), so whatever makes it late is
// the machine's, not the loop's. One floor sees one CPU only: in a virtual machine the host
// can deschedule one vCPU for a whole period of its CPU quota (about 100 ms) while the other
// runs on, and the haptic thread on that vCPU misses about 100 deadlines that a floor on the
// other never saw. So there is a floor pinned to each CPU of the process's affinity mask, and
// the loop is compared with the worst of them. Each floor also reports the steal time the
// host took from its CPU meanwhile (cpu_steal.h), which names such a stall for what it is.
// Units: ns inside, µs and ms in the report. Threads: start() and stop() from one thread;
// period_p99_us() from any while they run.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "common/util/histogram.h"

namespace cohaptic {

/// A period histogram [ns] as the reports give it: {"p50", "p99", "max"} in µs.
nlohmann::json quantiles_us(const Histogram& period_ns);

/// One bare timer loop, for run() on its own thread.
struct TimerFloor {
  Histogram period_ns{1000, 50000};
  std::uint64_t missed_deadlines = 0;
  bool pinned = false;              ///< stayed on the CPU it was given (the affinity took)
  std::uint64_t wakes_off_cpu = 0;  ///< wake-ups on another CPU than that one
  /// Sleeps to absolute deadlines at `rate_hz` until `stop`, pinned to `cpu` if >= 0.
  void run(double rate_hz, const std::atomic<bool>& stop, bool realtime, int cpu = -1);
};

class TimerFloors {
 public:
  /// One floor for each CPU this process may run on (one unpinned floor if the affinity
  /// mask cannot be read).
  TimerFloors();
  ~TimerFloors();
  TimerFloors(const TimerFloors&) = delete;
  TimerFloors& operator=(const TimerFloors&) = delete;

  void start(double rate_hz, bool realtime);
  void stop();

  std::size_t size() const { return floors_.size(); }
  int cpu(std::size_t i) const { return floors_[i].cpu; }
  const TimerFloor& floor(std::size_t i) const { return *floors_[i].floor; }
  /// The worst CPU's period p99 [µs] (the report's timer_floor.period_us.p99).
  double period_p99_us() const;
  /// After stop(): {"period_us": {p50, p99, max}, "missed_deadlines": n} as the worst CPU
  /// has them (each the largest over CPUs), and "cpus": each CPU's own, with its steal time.
  nlohmann::json report() const;

 private:
  struct OnCpu {
    int cpu = -1;  // -1: not pinned
    std::unique_ptr<TimerFloor> floor = std::make_unique<TimerFloor>();
    std::int64_t steal_at_start_ns = -1, steal_at_stop_ns = -1;  // -1: unknown
  };
  std::vector<OnCpu> floors_;
  std::vector<std::thread> threads_;
  std::atomic<bool> stop_{false};
};

}  // namespace cohaptic
