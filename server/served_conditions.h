// The conditions a session can switch between while it runs (a paired-comparison study's
// pair: `cohaptic-server --condition A:... --condition B:...`), and which one is served.
//
// A condition is what the paper's factors set: the protocol, the shift delay on every link
// (delay, jitter, loss), the step delay's held nodes, and the simulation rate's cap. The
// first condition is served from the start; a switch (ConditionSwitch::serve from the
// control socket, control_socket.h, or serve_next from a device button) takes effect at the
// simulation's next step, where it is recorded: protocol, held nodes and rate there, the
// links' delays with that step's outbox. Nothing a client is told names a condition: the clients
// learn only the protocol (wire::ProtocolSwitch), so a subject cannot tell which condition is
// which.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "common/delay/link_delay.h"
#include "common/util/monotonic_clock.h"

namespace cohaptic {

enum class ServeProtocol { p0, p1 };

struct ServedCondition {
  std::string name;
  ServeProtocol protocol = ServeProtocol::p1;
  double shift_delay_ms = 0, jitter_ms = 0, loss = 0;
  int step_nodes = 0;      ///< the step delay's held surface nodes (0: none)
  double sim_rate_hz = 0;  ///< the simulation loop's rate cap (0: up to 1 kHz)

  /// The link delay settings under this condition; reorder and seed are the session's.
  LinkDelaySettings link_delay(const LinkDelaySettings& session) const;
  std::string describe() const;  ///< e.g. "P1, shift 30 ms, 150 held nodes"
};

/// Parses `NAME:key=value,...` (keys protocol, shift_ms, jitter_ms, loss, step_nodes,
/// sim_rate_hz; unset keys: P1 and 0). Throws Error naming the text and the bad key or value.
ServedCondition parse_served_condition(const std::string& text);

/// The condition served now, shared by the I/O thread (which switches) and the simulation
/// thread (which applies a switch at its next step). Thread-safe.
class ConditionSwitch {
 public:
  /// `conditions`: at least one, names distinct (throws Error otherwise); the first is served.
  explicit ConditionSwitch(std::vector<ServedCondition> conditions);

  const std::vector<ServedCondition>& conditions() const { return conditions_; }

  /// Serves the condition named `name` from now; returns its index. Throws Error naming the
  /// known conditions when there is none of that name.
  int serve(const std::string& name);
  /// Serves the condition after the one served now (the first after the last); returns it.
  int serve_next();

  /// The condition served and how many switches led to it (0 at the start).
  struct Served {
    int index = 0;
    std::uint64_t switches = 0;
  };
  Served served() const;

  /// One switch asked for: when (monotonic_now_ns), and the condition it serves.
  struct Switch {
    std::int64_t time_ns = 0;
    int index = 0;
  };
  /// Every switch asked for so far, in order (the report's switch log).
  std::vector<Switch> history() const;

 private:
  int switch_to(int index);  // with mutex_ held

  const std::vector<ServedCondition> conditions_;
  mutable std::mutex mutex_;
  Served served_;
  std::vector<Switch> history_;
};

}  // namespace cohaptic
