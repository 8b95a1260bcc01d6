// LiveView: the server's live view (`cohaptic-server --view HOST:PORT`, README.md, "The
// live view"). It owns the ViewServer (view_server.h, its own thread) and turns what the
// server has into view.proto messages:
//   - the Scene, once (built at construction; recorded as /view_scene with --record);
//   - a Frame every 1/rate s, from the simulation thread: publish_frame() builds it from the
//     step's state and the displacement the loop solved, and hands it over newest-wins, so
//     the simulation never waits on a browser (recorded as /view_frames);
//   - the Status, from the I/O thread, whenever a user reports (publish_status()).
// Units: m, N, s, as view.proto.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "cohaptic/messages.pb.h"
#include "common/fem/compliance.h"
#include "common/model/model.h"
#include "common/model/shown_surface.h"
#include "common/sim/simulation.h"
#include "proto/record/session_recorder.h"
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
  /// Binds the view's port and records the scene (`recorder` may be null). `model` and
  /// `columns` must outlive it. Throws Error (a missing asset, an address in use, a bad
  /// token file).
  LiveView(const Model& model, const ComplianceColumns& columns, wire::Protocol protocol, const record::InjectedDelays& injected,
           LiveViewOptions options, record::SessionRecorder* recorder);

  void start() { server_.start(); }
  void stop() { server_.stop(); }
  std::string url() const { return server_.url(); }
  std::uint16_t port() const { return server_.port(); }
  ViewCounters counters() const { return server_.counters(); }

  /// The nodes whose displacement publish_frame() expects, in order.
  const std::vector<int>& nodes() const { return shown_.nodes; }
  /// True when a frame is due at `now_ns` (simulation thread).
  bool frame_due(std::int64_t now_ns) const { return now_ns - last_frame_ns_ >= period_ns_; }
  /// Builds, records and publishes the frame of the state after a step (simulation thread):
  /// `steps` is the loop's count so far, for the rate shown.
  void publish_frame(std::int64_t now_ns, double time, const Simulation& simulation, const Eigen::Matrix3Xd& displacement,
                     const std::vector<ToolState>& tools, std::uint64_t steps);
  /// A user's status report (I/O thread).
  void publish_status(int slot, const std::string& user, const wire::ClientStatus& status, double time);

 private:
  ShownSurface shown_;
  ShownIndex index_;
  record::SessionRecorder* recorder_;
  std::int64_t period_ns_;
  ViewServer server_;
  // Simulation thread.
  std::int64_t last_frame_ns_ = 0;
  std::uint64_t sequence_ = 0, last_steps_ = 0;
  // I/O thread.
  std::map<int, UserStatus> statuses_;
};

/// A ServerMessage holding `body` (one of view.proto's message types), serialized.
template <class Body>
std::string server_message(Body body) {
  ServerMessage message;
  if constexpr (std::is_same_v<Body, Scene>) *message.mutable_scene() = std::move(body);
  else if constexpr (std::is_same_v<Body, Frame>) *message.mutable_frame() = std::move(body);
  else if constexpr (std::is_same_v<Body, Status>) *message.mutable_status() = std::move(body);
  else *message.mutable_timeline() = std::move(body);
  return message.SerializeAsString();
}

}  // namespace cohaptic::view
