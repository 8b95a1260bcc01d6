// A session recording read back whole (for replay, exports and tests): the configuration
// and every message, by kind, in recording order. A truncated recording (its writer was
// killed) reads up to its last complete record and says so.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "cohaptic/recording.pb.h"
#include "cohaptic/view.pb.h"

namespace cohaptic::record {

struct Recording {
  std::filesystem::path file;
  SessionConfig config;
  bool has_config = false;
  std::vector<ReceivedDatagram> datagrams;
  std::vector<RecordedIr> irs;
  std::vector<HapticTick> ticks;
  std::vector<SimulationStep> steps;
  std::vector<SessionEvent> events;
  std::vector<ReceivedClientStatus> client_statuses;  ///< server: the users' status reports
  std::vector<view::Scene> view_scenes;               ///< server with --view: its live view's scene (one)
  std::vector<view::Frame> view_frames;               ///< and every frame
  bool truncated = false;
  std::string truncation;         ///< where, if truncated
  std::size_t unknown_messages = 0;  ///< on channels this build does not know
};

/// Reads `file`. Throws cohaptic::Error naming it if it is not a recording.
Recording read_recording(const std::filesystem::path& file);

}  // namespace cohaptic::record
