#include "client/cpu_steal.h"

#include <unistd.h>

#include <fstream>
#include <sstream>
#include <string>

namespace cohaptic {

std::vector<std::int64_t> cpu_steal_ns() {
  std::vector<std::int64_t> steal;
  std::ifstream stat("/proc/stat");
  const long ticks_per_s = sysconf(_SC_CLK_TCK);
  if (!stat || ticks_per_s <= 0) return steal;
  std::string line;
  while (std::getline(stat, line)) {
    // "cpuN user nice system idle iowait irq softirq steal ...": the aggregate "cpu " line
    // and every other line are skipped.
    if (line.size() < 4 || line.compare(0, 3, "cpu") != 0 || line[3] < '0' || line[3] > '9')
      continue;
    std::istringstream fields(line.substr(3));
    std::size_t cpu = 0;
    std::int64_t value = 0, steal_ticks = -1;
    fields >> cpu;
    for (int column = 0; column < 8 && fields >> value; ++column)
      steal_ticks = column == 7 ? value : -1;
    if (steal_ticks < 0) continue;  // an older kernel without the column
    if (steal.size() <= cpu) steal.resize(cpu + 1, -1);
    steal[cpu] = steal_ticks * (1'000'000'000 / ticks_per_s);
  }
  return steal;
}

}  // namespace cohaptic
