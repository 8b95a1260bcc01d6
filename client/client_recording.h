// What the client records of a session (--record FILE), through record::SessionRecorder
// (proto/record/session_recorder.h): the configuration first (who, with what device,
// in which session and slot), then from the I/O thread every datagram and IR received,
// every event, and every haptic tick the haptic thread traced (TickRecord ->
// HapticTick). `cohaptic-lab replay --verify` re-computes the ticks' forces.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "client/haptic_loop.h"
#include "cohaptic/recording.pb.h"

namespace cohaptic {

struct WelcomeInfo;

/// The first record. `welcome`: the session joined, if any yet.
record::SessionConfig client_session_config(const std::string& user, const std::string& device,
                                            double force_limit, std::uint64_t session,
                                            const std::optional<WelcomeInfo>& welcome,
                                            std::int64_t start_time_ns);

/// One haptic tick as recorded.
record::HapticTick haptic_tick_record(const TickRecord& tick);

}  // namespace cohaptic
