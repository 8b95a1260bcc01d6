// IrEncoder: turns the IRs the simulation builds into what travels and what is recorded.
// Each new IR is recorded whole (--record) and, under P1, becomes its user's control frame:
// a block of the user's zstd IR stream (a sphere body's IR, or compliance rows) or the IR
// whole. A sphere IR of a few hundred row nodes holds a dense normal compliance of a few
// hundred kB, and its conversion, recording and compression cost milliseconds: run() of the
// simulation loop hands them to this encoder's own thread, so that they delay only that IR,
// not the steps (and keep-alives) after it. encode() does the same work on the caller's
// thread (SimulationLoop::step, for callers that step the loop themselves).
//
// Order: one thread takes the IRs in the order posted, so each user's stream and the
// recording keep the simulation's order; within a batch, each user's IRs are framed in order
// on a thread of their own (the users' streams are independent), so one user's compression
// does not delay another's IR. It takes every step waiting at once, and of a
// user's IRs that travel whole (not as compliance rows) sends only the newest: one that a
// newer one replaced before it could leave is recorded, not sent (superseded in the
// report), so that a burst of rebuilds does not queue IRs that are stale on arrival. The
// batch's frames are handed over before its IRs are recorded, so the newest IR never
// waits for the recording of those before it.
// Backpressure: post() blocks while
// kMaxQueuedSteps steps' IRs wait, so a slow encoder slows the simulation (visible in its
// step rate) instead of growing a queue. A block that fails to encode (zstd) is logged and
// dropped, and the user is marked for a fresh start (take_restarts()): its next streamed IR
// must begin a new stream. Not copyable; encode() must not be called while the thread runs.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <thread>
#include <vector>

#include "common/ir/evaluate_force.h"
#include "proto/record/session_recorder.h"
#include "proto/wire/ir_stream.h"
#include "server/loop_statistics.h"
#include "server/outbox.h"

namespace cohaptic {

/// One IR a step built, to encode.
struct BuiltIr {
  std::int64_t time_ns = 0;  ///< the step's start (the recording's time of the IR)
  int user = 0;
  std::shared_ptr<const PreparedIR> built;  ///< as built: what the recording keeps
  /// What travels instead of `built`, if not it (compliance rows).
  std::optional<IntermediateRepresentation> as_sent;
  bool send = false;      ///< P1: to the user; else recorded only
  bool streamed = false;  ///< in the user's IR stream
  bool fresh = false;     ///< the stream starts afresh with it
  bool repeat = false;    ///< built by an earlier step, sent again (a switch to P1)
  /// The step switched to P1: the outbox tells every user so before its IRs, on the same
  /// connection, so that each client has the switch before the IR it changes over with.
  bool announces_p1 = false;
};

class IrEncoder {
 public:
  /// Steps' IRs that may wait for the thread before post() blocks.
  static constexpr std::size_t kMaxQueuedSteps = 16;

  /// `recorder` may be null; it and `statistics` must outlive the encoder.
  IrEncoder(int users, record::SessionRecorder* recorder, LoopStatistics& statistics);
  ~IrEncoder();
  IrEncoder(const IrEncoder&) = delete;
  IrEncoder& operator=(const IrEncoder&) = delete;

  /// Encodes `irs` (in order; a superseded IR's fresh start passes to the next) on the
  /// calling thread, appending the frames to `outbox`.
  void encode(std::vector<BuiltIr>& irs, Outbox& outbox);

  /// Starts the thread: each post()ed step's frames go to `send` (which must not block) in
  /// one outbox.
  void start(std::function<void(Outbox&&)> send);
  /// Queues one step's IRs for the thread.
  void post(std::vector<BuiltIr> irs);
  /// Encodes and sends whatever is queued, then joins the thread.
  void stop();

  /// The users whose stream broke since the last call (their next streamed IR must be fresh).
  std::vector<int> take_restarts();

 private:
  /// What the recording keeps of one IR once its frame is made: the stream block that held
  /// it whole, or its wire form if framing made it (else it is made when recorded).
  struct ToRecord {
    std::optional<wire::CompressedIr> block;
    std::optional<wire::IntermediateRepresentation> whole;
  };
  /// One user's frames, in order, and their bytes.
  struct UserFrames {
    std::vector<ToSlot<wire::Control>> frames;
    std::uint64_t bytes = 0;
  };
  /// The frames of `irs` into `outbox`; what the recording needs of them (empty without a
  /// recorder).
  std::vector<ToRecord> frame(std::vector<BuiltIr>& irs, Outbox& outbox);
  /// The frames of irs[i] for i in `indices` (one user's, in order), filling their
  /// to_record[i]; called for different users at once.
  UserFrames frame_user(const std::vector<BuiltIr>& irs, std::span<const std::size_t> indices,
                        std::vector<ToRecord>& to_record);
  /// Records every IR of `irs`, in order.
  void record(const std::vector<BuiltIr>& irs, std::vector<ToRecord> to_record);
  void run();

  record::SessionRecorder* recorder_;
  LoopStatistics& statistics_;
  std::vector<wire::IrStreamWriter> streams_;  // per user
  std::function<void(Outbox&&)> send_;

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::vector<BuiltIr>> queue_;
  std::vector<int> restarts_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace cohaptic
