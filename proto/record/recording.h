// A session recording read back whole (for replay, exports and tests): the configuration
// and every message, by kind, in recording order. A truncated recording (its writer was
// killed) reads up to its last complete record (its last complete chunk) and says so, and
// how far CRCs vouch for what it holds.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "cohaptic/recording.pb.h"
#include "cohaptic/view.pb.h"
#include "proto/record/mcap_records.h"

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
  std::vector<view::Scene> view_scenes;  ///< server with --view: its live view's scene (one)
  std::vector<view::Frame> view_frames;  ///< and every frame
  bool truncated = false;
  std::string truncation;        ///< where, if truncated
  std::uint64_t file_bytes = 0;  ///< the file's size
  McapCrcCoverage crc;           ///< which of its messages a checked CRC covers (mcap_records.h)
  std::size_t unknown_messages = 0;  ///< on channels this build does not know
};

/// Reads `file`. Throws cohaptic::Error naming it if it is not a recording, or if a CRC in
/// it does not match (a damaged chunk, say).
Recording read_recording(const std::filesystem::path& file);

/// For a truncated recording, one line saying how far its CRCs vouch for it, with times in s
/// from its configuration's start_time_ns, e.g. "cut short at byte 81234: everything up to
/// t = 12.345 s is checked by its chunks' CRCs"; empty for a complete one.
std::string describe_cut(const Recording& recording);

}  // namespace cohaptic::record
