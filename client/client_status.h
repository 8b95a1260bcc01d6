// The status a client reports to the server while it runs (wire::ClientStatus, for the
// server's live view): its haptic figures so far, computed exactly as its report computes
// them at the end (docs/reports.md "Client report"), so the final status equals the report.
// Units on the wire: Hz, µs, ms, N, s.
#pragma once

#include "cohaptic/messages.pb.h"
#include "common/util/histogram.h"
#include "client/haptic_loop.h"

namespace cohaptic {

/// How often a status is sent (and once more, final, before the client's goodbye).
inline constexpr std::int64_t kStatusPeriod_ms = 200;

/// The figures from the haptic loop's progress and histograms, the timer floors' period
/// p99 (the worst CPU's, TimerFloors::period_p99_us) and the one-way delays the clock measured.
wire::ClientStatus client_status(const HapticProgress& progress, const HapticMetrics& metrics,
                                 double timer_floor_p99_us, const Histogram& one_way_delay_ns);

}  // namespace cohaptic
