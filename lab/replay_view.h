// `cohaptic-lab replay FILE --view HOST:PORT`: a server recording in the live view's page,
// with a timeline (view/replay_player.h). It serves until SIGINT or SIGTERM, moving the
// playback on 30 times a second and sending every browser what changed: the frame, the
// users' status at that time, the timeline.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "proto/record/recording.h"

namespace cohaptic {

struct ReplayViewOptions {
  std::string host = "127.0.0.1";
  std::uint16_t port = 0;
  std::optional<std::filesystem::path> token_file;  ///< required off loopback (view/view_token.h)
};

/// Serves `recording` until a signal; returns the exit code (0). Throws Error if the
/// recording has no view frames or the port cannot be bound.
int serve_replay(const record::Recording& recording, const ReplayViewOptions& options);

}  // namespace cohaptic
