// SessionRecorder: one process's recording of a session, in MCAP with the protobuf schemas
// embedded (opens in Foxglove Studio / Lichtblick). One channel per recording.proto type:
//   /config (SessionConfig, first), /datagrams_in (ReceivedDatagram), /ir (RecordedIr),
//   /haptic (HapticTick, clients), /steps (SimulationStep, the server), /events; the server
//   also /client_status (ReceivedClientStatus) and, with --view, /view_scene and
//   /view_frames (view.proto's Scene and Frame, as its browsers get them).
// Log times are the recording process's monotonic nanoseconds. Records are flushed at least
// every 100 ms, so a killed process leaves a file readable up to its last complete record.
//
// Thread-safe: the server records from its I/O and simulation threads. A write failure
// (a full disk, say) never stops the session: it is logged once, with the reason, the
// recording stops there, and failed() tells.
#pragma once

#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "cohaptic/recording.pb.h"
#include "cohaptic/view.pb.h"

namespace cohaptic::record {

class McapWriter;

/// Topic names, shared with readers.
namespace topic {
inline constexpr const char* kConfig = "/config";
inline constexpr const char* kDatagramsIn = "/datagrams_in";
inline constexpr const char* kIr = "/ir";
inline constexpr const char* kHaptic = "/haptic";
inline constexpr const char* kSteps = "/steps";
inline constexpr const char* kEvents = "/events";
inline constexpr const char* kClientStatus = "/client_status";
inline constexpr const char* kViewScene = "/view_scene";
inline constexpr const char* kViewFrames = "/view_frames";
}  // namespace topic

/// The user an event is about.
struct EventUser {
  std::string name;
  std::uint32_t slot = 0;
};

class SessionRecorder {
 public:
  /// Creates the file (throws cohaptic::Error naming it if it cannot).
  explicit SessionRecorder(const std::filesystem::path& file);
  ~SessionRecorder();
  SessionRecorder(const SessionRecorder&) = delete;
  SessionRecorder& operator=(const SessionRecorder&) = delete;

  void config(const SessionConfig& config);
  void datagram_in(std::int64_t receive_ns, const wire::Datagram& datagram);
  /// `repeat`: built by an earlier step, sent again (RecordedIr.repeat).
  /// `warm_start`: a client's, if it warmed the IR's contact solve (recording.proto).
  void ir(std::int64_t time_ns, const wire::IntermediateRepresentation& ir, bool repeat = false,
          const WarmStart* warm_start = nullptr);
  /// An IR as the block of IR stream `stream` it travelled in (recording.proto, RecordedIr):
  /// the blocks of a stream must be recorded in order, none left out.
  void ir_block(std::int64_t time_ns, std::uint32_t stream, const wire::CompressedIr& block,
                bool repeat = false, const WarmStart* warm_start = nullptr);
  void tick(const HapticTick& tick);
  void step(const SimulationStep& step);
  /// An event; joins and leaves name their user and slot, so a user can be found by name.
  void event(std::int64_t time_ns, const std::string& kind, const std::string& text,
             const std::optional<EventUser>& user = std::nullopt);
  void client_status(const ReceivedClientStatus& status);
  void view_scene(std::int64_t time_ns, const view::Scene& scene);
  void view_frame(std::int64_t time_ns, const view::Frame& frame);
  /// Hands buffered records to the file if the flush interval has passed.
  void flush_if_due();
  /// Writes the summary and footer; later records are dropped.
  void close();

  bool failed() const;
  const std::filesystem::path& file() const { return file_; }

 private:
  void write(std::uint16_t channel, std::int64_t time_ns,
             const google::protobuf::MessageLite& message);

  std::filesystem::path file_;
  mutable std::mutex mutex_;
  std::unique_ptr<McapWriter> writer_;
  std::uint16_t config_ = 0, datagrams_ = 0, ir_ = 0, haptic_ = 0, steps_ = 0, events_ = 0;
  std::uint16_t client_status_ = 0, view_scene_ = 0, view_frames_ = 0;
  std::uint32_t sequence_ = 0;
  bool failed_ = false;
};

}  // namespace cohaptic::record
