// The server's share of the CPUs against the machine's other programs. On a small machine a
// browser drawing the live view in software takes as much CPU as the simulation, whose IRs
// then come late and the users' forces fade; a lower nice value gives the simulation the
// larger share (CFS weighs nice -10 about ten times nice 0) without taking a core outright,
// as SCHED_FIFO would. The haptic clients are not affected: their loops run SCHED_FIFO.
#pragma once

namespace cohaptic {

/// The nice value the server asks for.
constexpr int kServerNice = -10;

/// Sets the calling thread's nice value to `nice` (Linux: per thread; the threads it starts
/// afterwards inherit it). False, changing nothing, where not permitted: without root,
/// CAP_SYS_NICE or an RLIMIT_NICE that allows it.
bool raise_priority(int nice);

}  // namespace cohaptic
