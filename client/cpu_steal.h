// cpu_steal_ns: how long the hypervisor has kept each CPU of this virtual machine from
// running (the "steal" column of /proc/stat), since boot. A vCPU the host deschedules (a
// host CPU quota used up, say) stops every thread on it, a real-time one included, and the
// guest only sees it afterwards, as steal time: the client reports it beside its timer
// floors so that such a stall is told apart from the loop's own lateness.
// Units: ns. Index: the CPU's number; -1 for a number /proc/stat does not list. Empty when
// /proc/stat cannot be read (not Linux). Reads a file: never on the haptic thread.
#pragma once

#include <cstdint>
#include <vector>

namespace cohaptic {

std::vector<std::int64_t> cpu_steal_ns();

}  // namespace cohaptic
