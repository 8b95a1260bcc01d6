// HapticLoop: the client's real-time loop (docs/architecture.md "2. Threads and who owns what").
//
// Every period, at an absolute deadline (clock_nanosleep on CLOCK_MONOTONIC), it reads the
// device, hands the own tool sample to the I/O thread, takes in remote tool samples and the
// newest IR (P1) or force (P0), computes the force, makes it safe and writes it to the
// device. It takes no lock, allocates nothing and makes no system call but the device's
// and the sleep: everything crosses threads through SpscRing and TripleBuffer.
//
// Late ticks: if it wakes after the next deadline, the missed ticks are skipped and counted
// and the schedule keeps its phase (no catch-up burst, no drift).
// Safety: the force is limited to min(device, scene) limit; an IR the server has not
// confirmed for `max_age` (P1: since its last confirmation, or its arrival; while the
// server's newer IR is on its way the one in use is confirmed no more), or a force (P0)
// older than that, fades the force to zero over `fade`; any non-finite value gives zero and
// an event. Units: s, m, N; times are CLOCK_MONOTONIC ns
// (HapticClock::monotonic(); a test may give the loop a clock it drives instead).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>

#include "common/haptics/fade_tally.h"
#include "common/haptics/ir_age_histogram.h"
#include "common/haptics/haptic_device.h"
#include "common/haptics/passivity_controller.h"
#include "common/ir/evaluate_force.h"
#include "common/sync/remote_tool_buffer.h"
#include "common/util/histogram.h"
#include "common/util/spsc_ring.h"
#include "common/util/triple_buffer.h"
#include "proto/wire/header.h"

namespace cohaptic {

enum class HapticProtocol { p0, p1 };

struct HapticLoopSettings {
  double rate_hz = 1000;
  HapticProtocol protocol = HapticProtocol::p1;
  double force_limit = 3.3;  ///< [N], min of the device's and the scene's
  double max_age_s = 0.25;   ///< IR (P1) or force (P0) older than this starts to fade
  double fade_s = 0.1;       ///< time to fade to zero
  PlayoutPolicy playout = PlayoutPolicy::fixed;
  double playout_delay_s = 0.005;
  double duration_s = 0;  ///< 0: until stopped
  bool realtime = true;   ///< try SCHED_FIFO and mlockall
  /// Filter the output through a passivity observer/controller (passivity_controller.h)
  /// before the force limit: keeps a stiff, delayed or stepwise force passive for the hand.
  bool passivity_control = false;
  double passivity_mass_kg = 0.2;  ///< the lightest mass expected at the tool (caps its damping)
};

/// An IR handed to the haptic thread with its fresh evaluation states (made on the I/O
/// thread; after the swap the haptic thread is their only user) and when it arrived.
struct IrSlot {
  std::unique_ptr<const PreparedIR> ir;
  std::unique_ptr<EvaluationState> state;
  /// The coupling figure's evaluation without the remote tools: its own state, so that
  /// neither evaluation disturbs the other's (a sphere body's contact solve is kept).
  std::unique_ptr<EvaluationState> alone_state;
  std::int64_t arrival_ns = 0;
  /// evaluation_moves_the_body(*state), decided here once rather than on every tick.
  bool body_moves = false;
  /// evaluation_measures_elapsed_time(*state), likewise.
  bool measures_elapsed = false;
};

/// The slot for `ir` with the state its evaluation starts from (off the haptic thread).
IrSlot make_ir_slot(std::unique_ptr<const PreparedIR> ir, std::int64_t arrival_ns);

/// The server's latest confirmation that an IR is still valid (P1), with when it arrived.
struct IrConfirmation {
  std::uint64_t epoch = 0;
  std::int64_t arrival_ns = 0;
};

/// The protocol the server serves from `since_ns` on (a session switching conditions), as
/// the I/O thread learnt it. The loop changes over once the first IR (P1) or force (P0) that
/// arrived at or after `since_ns` is there, so the force never lapses.
struct ProtocolChange {
  HapticProtocol protocol = HapticProtocol::p1;
  std::int64_t since_ns = 0;
};

/// A P0 force from the server, with when it arrived.
struct ForceSlot {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  std::int64_t arrival_ns = 0;
  std::uint64_t epoch = 0;
  bool valid = false;
};

struct RemoteSample {
  std::uint32_t user = 0;
  std::int64_t sample_time_ns = 0;  ///< local clock
  std::int64_t arrival_ns = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  bool valid = false;
};

struct OwnSample {
  std::int64_t sample_time_ns = 0;  ///< local clock
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::uint32_t buttons = 0;
  bool valid = false;
};

/// One tick, for the recording and offline checks.
struct TickRecord {
  std::int64_t time_ns = 0;
  Eigen::Vector3d own = Eigen::Vector3d::Zero();
  std::uint32_t buttons = 0;  ///< the own tool's, as evaluated
  bool own_valid = false;
  std::uint8_t remote_count = 0;  ///< remote positions used
  std::array<Eigen::Vector3d, kMaxUsers - 1>
      remotes{};                                    ///< in the IR's remotes order (NaN: unknown)
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< as written to the device
  Eigen::Vector3d evaluated = Eigen::Vector3d::Zero();  ///< before fading and limiting
  std::uint64_t ir_epoch = 0;
  double dt = 0;  ///< the period the evaluation advanced by [s] (P1)
  std::uint8_t flags = 0;
  float fade = 1;
  std::int64_t ir_age_ns = -1;                   ///< of the IR or force used (-1: none yet)
  HapticProtocol protocol = HapticProtocol::p1;  ///< the protocol the tick used
};

enum class HapticEventKind : std::uint8_t {
  non_finite,
  ir_switched,
  fading,
  started_realtime,
  realtime_refused
};
struct HapticEvent {
  HapticEventKind kind = HapticEventKind::non_finite;
  std::int64_t time_ns = 0;
  std::uint64_t value = 0;
};

/// The loop's running totals, published every tick and once more when it ends (finished),
/// for the status the I/O thread reports to the server (client_status.h). Its histograms
/// are read from HapticLoop::metrics() directly (Histogram allows a concurrent reader).
struct HapticProgress {
  std::uint64_t ticks = 0, missed_deadlines = 0, clamped = 0;
  double elapsed_s = 0;   ///< since the loop started; when finished, HapticMetrics::elapsed_s
  double peak_force = 0;  ///< [N]
  FadeTally fades;
  bool finished = false;
};

/// Lock-free channels between the I/O thread and the haptic thread.
struct HapticChannels {
  TripleBuffer<IrSlot> ir;                      // I/O -> haptic (P1)
  TripleBuffer<IrConfirmation> confirmation;    // I/O -> haptic (P1)
  TripleBuffer<ForceSlot> force;                // I/O -> haptic (P0)
  TripleBuffer<ProtocolChange> protocol;        // I/O -> haptic: a switch of the protocol served
  SpscRing<RemoteSample, 4096> remote_samples;  // I/O -> haptic
  SpscRing<OwnSample, 4096> own_samples;        // haptic -> I/O
  SpscRing<TickRecord, 8192> trace;             // haptic -> I/O (only if tracing: recording)
  SpscRing<HapticEvent, 1024> events;           // haptic -> I/O
  TripleBuffer<HapticProgress> progress;        // haptic -> I/O
  std::atomic<bool> tracing{false};
};

struct HapticMetrics {
  Histogram period_ns{1000, 50000};  ///< 1 us bins up to 50 ms
  Histogram ir_age_ns = ir_age_histogram();
  std::uint64_t ticks = 0, missed_deadlines = 0, non_finite = 0, clamped = 0, ir_switches = 0;
  std::uint64_t protocol_switches = 0;  ///< changes of the protocol in use (the server switched it)
  std::uint64_t contact_unresolved =
      0;                     ///< ticks that held the last force (sphere solve unfinished)
  double peak_force = 0;     ///< [N]
  double peak_coupling = 0;  ///< [N], |F - F without the remote tools|
  /// Whether peak_coupling was measured: only while in contact with a body whose evaluation
  /// keeps no state (a second evaluation would advance a dynamic body twice).
  bool coupling_measured = false;
  double largest_step_on_ir_switch = 0;  ///< [N]
  FadeTally fades;  ///< the fades the user felt, ticks counted at the nominal period
  double elapsed_s = 0;
  bool realtime = false;  ///< SCHED_FIFO and mlockall in effect
};

/// Where the loop reads the time and sleeps to its deadlines, in ns. The real clock,
/// monotonic(), is CLOCK_MONOTONIC, on which the I/O thread stamps arrivals. A test passes
/// a clock it drives (`context` is its state) to put every tick at an exact time. Plain
/// function pointers fixed at construction: two indirect calls a tick, no allocation, no lock.
struct HapticClock {
  std::int64_t (*now_ns)(void* context);
  void (*sleep_until_ns)(void* context,
                         std::int64_t deadline_ns);  ///< returns at or after the deadline
  void* context = nullptr;
  static HapticClock monotonic();
};

class HapticLoop {
 public:
  HapticLoop(HapticDevice& device, HapticChannels& channels, HapticLoopSettings settings,
             HapticClock clock = HapticClock::monotonic());

  /// Runs until `stop` is set, the duration is over or a scripted device finishes.
  void run(const std::atomic<bool>& stop);
  const HapticMetrics& metrics() const { return metrics_; }
  /// The passivity controller (idle unless settings.passivity_control): what it did.
  const PassivityController& passivity() const { return passivity_; }

 private:
  Eigen::Vector3d compute_force(std::int64_t now, const Eigen::Vector3d& own, TickRecord& record);
  /// Takes in the newest IR (P1) or force (P0), changing protocols when the server switched
  /// and what the new one needs has arrived; true if what the tick uses is new.
  bool take_in_server_updates();
  void publish_progress(double elapsed_s, bool finished);
  std::int64_t now() const { return clock_.now_ns(clock_.context); }

  HapticDevice& device_;
  HapticChannels& channels_;
  HapticLoopSettings settings_;
  HapticProtocol protocol_;  // in use: settings_.protocol until the server switches it
  HapticMetrics metrics_;
  std::array<RemoteToolBuffer, kMaxUsers> remote_buffers_;
  Eigen::Vector3d last_force_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_evaluated_ = Eigen::Vector3d::Zero();  // the IR's last resolved force
  EvaluationCarry carry_;               // what the evaluator in use hands on to the next IR's
  std::int64_t last_evaluated_ns_ = 0;  // when the last IR evaluation's tick woke
  const PreparedIR* confirmed_ir_ =
      nullptr;  // the IR in use, and when the server last confirmed it
  std::int64_t confirmed_ns_ = 0;
  PassivityController passivity_;
  HapticClock clock_;
};

/// A loop that woke at `woke` for `deadline` (ns) and finds the next deadline passed too:
/// moves `deadline` past the missed ones, keeping the phase, and returns how many whole
/// periods were missed (0 if on time). Shared by the haptic loop and its timer floors.
std::uint64_t skip_missed_deadlines(std::int64_t& deadline, std::int64_t woke, std::int64_t period);

/// Locks the process's memory (mlockall, MCL_CURRENT | MCL_FUTURE) once: later calls return
/// the first call's result without locking again (every mapping made since is locked by
/// MCL_FUTURE). Locking populates the whole address space, up to hundreds of ms of kernel
/// work (116 ms for a 200 MB process on a 2-core VM); a real-time thread doing it would hold
/// its CPU that long, stalling the timer floor there, so cohaptic-client calls this on its
/// main thread before any real-time thread starts.
/// Never throws.
bool lock_process_memory();

/// Tries SCHED_FIFO (priority `priority`) for the calling thread and lock_process_memory();
/// returns whether both took effect. Never throws.
bool enter_realtime(int priority);

}  // namespace cohaptic
