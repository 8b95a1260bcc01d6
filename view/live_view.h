// LiveView: the server's live view (`cohaptic-server --view HOST:PORT`, docs/live-view.md
// "The live view"). It owns the ViewServer (view_server.h, its own thread) and turns what the
// server has into view.proto messages:
//   - the Scene, once (built at construction; recorded as /view_scene with --record);
//   - a Frame every 1/rate s while a browser watches or the session is recorded (nothing is
//     computed for a view nobody watches): the simulation thread hands over the step's
//     FrameState (view_messages.h: tools, forces, each body's BodyFrameState), newest
//     wins, and the view's own thread computes the surface's displacement, encodes, records
//     (/view_frames) and sends the frame, so the simulation neither waits on a browser nor
//     spends its time on the drawing;
//   - the Status, from the I/O thread, whenever a user reports (publish_status()).
// Units: m, N, s, as view.proto.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "common/fem/compliance.h"
#include "common/model/model.h"
#include "proto/record/session_recorder.h"
#include "view/shown_scene.h"
#include "view/view_messages.h"
#include "view/view_server.h"

namespace cohaptic::view {

/// Frames per second of the live view when --view-rate-hz is not given.
inline constexpr double kDefaultViewRate_hz = 30;

struct LiveViewOptions {
  std::string host = "127.0.0.1";
  std::uint16_t port = 0;
  std::optional<std::filesystem::path> token_file;  ///< access_token(): required off loopback
  double rate_hz = kDefaultViewRate_hz;
  std::filesystem::path assets = COHAPTIC_VIEW_WEB_DIR;  ///< view/web
  std::filesystem::path proto = COHAPTIC_PROTO_DIR;      ///< proto/
};

class LiveView {
 public:
  /// Binds the view's port and records the scene of every body of `model` (`recorder` may
  /// be null). columns[i]: body i's compliance columns, null unless it is linear elastic.
  /// `model` and the columns must outlive it. Throws Error (a missing asset, an address in
  /// use, a bad token file).
  LiveView(const Model& model, std::span<ComplianceColumns* const> columns, wire::Protocol protocol,
           const record::InjectedDelays& injected, LiveViewOptions options,
           record::SessionRecorder* recorder);

  void start() { server_.start(); }
  void stop() { server_.stop(); }
  std::string url(bool with_token = true) const { return server_.url(with_token); }
  std::uint16_t port() const { return server_.port(); }
  ViewCounters counters() const { return server_.counters(); }

  /// True when a frame is due at `now_ns` and someone will have it: a browser is connected,
  /// or the session is recorded (simulation thread). Frames are due every 1/rate s on
  /// average, whatever the steps' length (none to catch up after a gap).
  bool frame_due(std::int64_t now_ns) const {
    return now_ns >= next_frame_ns_ && (recorder_ || server_.watched());
  }
  /// Hands over the state after a step at `now_ns` (simulation thread; `steps`: the loop's
  /// count so far, for the rate shown). The frame is built, recorded and sent on the view's
  /// thread; a state still waiting there is replaced by this one (that frame is neither
  /// sent nor recorded).
  void publish_frame(std::int64_t now_ns, double time, FrameState state, std::uint64_t steps);
  /// Frames built so far (any thread).
  std::uint64_t frames_built() const { return sequence_.load(); }
  /// A user's status report (I/O thread).
  void publish_status(int slot, const std::string& user, const wire::ClientStatus& status,
                      double time);

 private:
  struct PendingFrame {
    std::int64_t time_ns = 0;
    double time = 0, sim_rate_hz = 0;
    FrameState state;
  };
  void build_frame();  // the view's thread

  ShownScene shown_;
  record::SessionRecorder* recorder_;
  std::int64_t period_ns_;
  // Simulation thread.
  std::int64_t last_frame_ns_ = 0, next_frame_ns_ = 0;
  std::uint64_t last_steps_ = 0;
  // Handed from the simulation thread to the view's.
  std::mutex pending_mutex_;
  std::optional<PendingFrame> pending_;
  // The view's thread (read anywhere).
  std::atomic<std::uint64_t> sequence_{0};
  // I/O thread.
  std::map<int, UserStatus> statuses_;
  // Last: its thread, which uses the members above, ends before they go.
  ViewServer server_;
};

/// A ServerMessage holding `body` (one of view.proto's message types), serialized.
template <class Body>
std::string server_message(Body body) {
  ServerMessage message;
  if constexpr (std::is_same_v<Body, Scene>)
    *message.mutable_scene() = std::move(body);
  else if constexpr (std::is_same_v<Body, Frame>)
    *message.mutable_frame() = std::move(body);
  else if constexpr (std::is_same_v<Body, Status>)
    *message.mutable_status() = std::move(body);
  else
    *message.mutable_timeline() = std::move(body);
  return message.SerializeAsString();
}

}  // namespace cohaptic::view
