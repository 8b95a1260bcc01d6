// SimulationLoop: the server's simulation thread. Each step
//   1. copies the latest tool samples (ToolInputs) and gives the simulation those that
//      are fresh (a tool silent for --client-timeout is released); takes in each FEM
//      body's compliance columns solved ahead, and asks for those near the tools and the
//      obstacles (CompliancePrefetch, one per FEM body);
//   2. steps the SceneSimulation: each body's (FEM: contacts, active sets, M~ when a set
//      changed; mass-spring: the whole network, and the IRs that are due);
//   3. fills the step's Outbox: the IR keep-alives (P1, every kKeepAlivePeriod_ns), the
//      forces (P0); and lists the step's new IRs for the IrEncoder, which records them and
//      (P1) turns them into each user's frames (ir_encoder.h);
//   4. every 1/--display-rate-hz, solves the surface displacement for the DisplayWriter;
//      every 1/--view-rate-hz, while a browser watches or the session is recorded, hands the
//      live view the state it draws of every body (view/body_frame_state.h: an FEM body's
//      loads, not its displacement: the view's thread computes that); one state solve per
//      FEM body when both are due;
//   5. records the step (--record), and its figures (LoopStatistics).
// A switch of the served condition (ConditionSwitch, served_conditions.h) takes effect at the
// start of the next step: the held nodes' count, the loop's rate and the protocol (the
// outbox tells every user; on a switch to P1 each user's current IR is sent again, so that
// its client has one to change over with) and the links' delays (with the outbox), recorded
// with that step. With --switch-button, a user's press of that button (counted as its
// samples arrive, so one between two steps counts too) serves the next condition from the
// following step.
// run() paces the steps at the loop's rate with absolute deadlines (when behind, the next
// step starts at once, with no catch-up burst) and hands each non-empty outbox to the I/O
// side; the new IRs go to the encoder's thread, which hands their frames over in outboxes
// of their own. It sleeps to the next deadline after every step, failed or not: a step that
// throws releases every tool and is counted, and logged at a paced rate (StepFailures);
// kMaxConsecutiveStepFailures in a row end the loop with the reason.
// The loop owns the SceneSimulation (the mutable state); the model is shared read-only, the
// FEM bodies' compliance columns are filled in by this thread alone (each prefetch worker
// solves into its own, handed over at the start of a step). The live view shows every body;
// the display a scene of one linear elastic object or of one home-spring tissue (its display
// deformation, no solve). Times: ns of
// monotonic_now_ns(); simulation time in s from the server's start.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "common/fem/compliance.h"
#include "common/ir/compliance_rows_sender.h"
#include "common/model/model.h"
#include "common/sim/scene_simulation.h"
#include "common/util/monotonic_clock.h"
#include "proto/record/session_recorder.h"
#include "server/compliance_prefetch.h"
#include "server/display_writer.h"
#include "server/ir_encoder.h"
#include "view/live_view.h"
#include "server/loop_statistics.h"
#include "server/outbox.h"
#include "server/serve_options.h"
#include "server/step_failures.h"
#include "server/tool_inputs.h"

namespace cohaptic {

/// P1: how often the server tells each client that its IR still stands. A client fades its
/// force out when these stop for its IR's max age (--ir-max-age, 0.5 s by default).
inline constexpr std::int64_t kKeepAlivePeriod_ns = 5'000'000;
/// The loop's rate when --sim-rate-hz is not given.
inline constexpr double kDefaultSimulationRate_hz = 1000;

class SimulationLoop {
 public:
  /// `display`, `view` and `recorder` may be null (no --display, --view, --record).
  /// Everything given must outlive the loop.
  /// columns[i]: body i's compliance columns (null unless it is linear elastic).
  /// `conditions` (may be null: the options' condition throughout): the condition served
  /// now, whose first is what `options` give.
  SimulationLoop(const Model& model, std::span<ComplianceColumns* const> columns,
                 const ServeOptions& options, ToolInputs& tools, LoopStatistics& statistics,
                 DisplayWriter* display, view::LiveView* view, record::SessionRecorder* recorder,
                 std::int64_t start_ns, ConditionSwitch* conditions = nullptr);

  /// One step at `now_ns`: returns what to send, its new IRs encoded on the calling thread.
  /// Throws whatever the simulation's step throws. Not while run() runs.
  Outbox step(std::int64_t now_ns);

  /// Steps until `running` turns false, handing each step's outbox, and the encoder's
  /// outboxes of IRs, to `send` (called from both threads: it must be thread-safe and not
  /// block). Returns once every IR built is encoded and handed over: why it stopped early,
  /// the last error after kMaxConsecutiveStepFailures failed steps in a row; nullopt when
  /// `running` ended it.
  std::optional<std::string> run(const std::atomic<bool>& running,
                                 const std::function<void(Outbox&&)>& send);

  const StepFailures& failures() const { return failures_; }

 private:
  /// A step's outbox, and its new IRs to encode.
  struct StepOutput {
    Outbox outbox;
    std::vector<BuiltIr> irs;
  };
  StepOutput advance(std::int64_t now_ns);
  /// Applies a switch of the served condition made since the last step, if any: what the
  /// step records of it.
  std::optional<record::ConditionSwitch> apply_condition_switch(Outbox& outbox);
  std::optional<std::string> step_until(const std::atomic<bool>& running,
                                        const std::function<void(Outbox&&)>& send);
  void take_tools(std::int64_t now_ns);
  /// The IRs that changed this step, as the encoder takes them.
  std::vector<BuiltIr> new_irs(std::int64_t now_ns);
  /// `ir` as compliance rows for `user`, if it is a condensed FEM body sent that way.
  bool to_compliance_rows(IntermediateRepresentation& ir, int user);
  /// `user` holds no rows and its stream starts afresh (a new user, another body, a lost block).
  void restart_rows(int user);
  void add_keep_alives(Outbox& outbox);
  std::vector<record::ServerForce> add_forces(Outbox& outbox);
  bool solve_display_frame(std::int64_t now_ns);
  void offer_display_frame(std::int64_t now_ns, Eigen::Matrix3Xd displacement);
  // The forces a view frame shows: P0's, as sent this step; under P1, evaluated for the view
  // alone (the server-held evaluations serve nothing else then).
  const std::vector<Eigen::Vector3d>& view_forces();
  double seconds_since_start(std::int64_t ns) const {
    return static_cast<double>(ns - start_ns_) * 1e-9;
  }

  // One compliance prefetch per FEM body, with the columns it fills.
  struct BodyPrefetch {
    ComplianceColumns* columns;
    int body;
    std::unique_ptr<CompliancePrefetch> worker;
  };
  void deliver_prefetched();

  const ServeOptions& options_;
  ConditionSwitch* conditions_;  // switched from here too: a device button
  std::uint64_t switches_applied_ = 0;
  ServeProtocol protocol_;   // served now
  double rate_hz_;           // the loop's rate now
  bool resend_irs_ = false;  // the next new_irs() sends every user's IR, changed or not
  ToolInputs& tools_;        // taken each step (which restarts its press counts)
  LoopStatistics& statistics_;
  DisplayWriter* display_;
  view::LiveView* view_;
  record::SessionRecorder* recorder_;
  std::vector<ComplianceColumns*> columns_;  // per body, null unless linear elastic
  std::int64_t start_ns_;
  SceneSimulation simulation_;
  StepFailures failures_;
  std::vector<ToolInput> latest_;  // this step's copy of the tool inputs
  std::vector<bool> used_;         // per slot: fresh, given to the simulation
  std::vector<BodyPrefetch> prefetch_;
  std::int64_t last_keep_alive_ns_ = 0, last_display_ns_ = 0;
  std::uint64_t steps_ = 0;                   // successful steps so far
  bool told_groove_record_full_ = false;      // the warning is logged once
  std::vector<view::ToolState> view_tools_;   // this step's tools, for the view
  std::vector<Eigen::Vector3d> view_forces_;  // per user, for the view [N]
  // Compliance rows: what each user's client holds (restarted when a new user takes the
  // slot), whether its zstd stream (the encoder's) has begun, and per body the mesh node
  // of each node tag.
  const Model& model_;
  bool compliance_rows_;
  std::vector<ComplianceRowsSender> rows_senders_;
  std::vector<int> rows_objects_;  // per user: the body its held rows are of
  std::vector<std::uint8_t>
      stream_started_;  // per user: its IR stream has a block the client holds
  std::vector<std::uint64_t> joins_seen_;
  std::vector<std::unordered_map<std::int64_t, int>> node_of_tag_;
  IrEncoder encoder_;
};

}  // namespace cohaptic
