// ReplayPlayer: a server recording played back in the live view's page
// (`cohaptic-lab replay FILE --view HOST:PORT`, docs/live-view.md, "The live view"). It holds what
// the recording has for the page (the view's Scene, with every frame's force magnitudes
// added for the charts, every Frame, the users' status reports, all in simulation time) and a
// playback position: play, pause, speed, seek, and jumps to the frame with the largest force and to
// the largest force step between two frames. One position for all browsers watching (they watch
// together). No threads: the caller moves it on with advance() and sends what changed. Units: s, N.
#pragma once

#include <cstddef>
#include <vector>

#include "cohaptic/view.pb.h"
#include "proto/record/recording.h"

namespace cohaptic::view {

class ReplayPlayer {
 public:
  /// Takes the recording's view scene, frames and status reports. Throws Error, naming
  /// the file, if it was recorded without --view (no frames).
  explicit ReplayPlayer(const record::Recording& recording);

  const Scene& scene() const { return scene_; }
  double time() const { return time_; }
  bool playing() const { return playing_; }
  /// The frame shown: the last one at or before time().
  std::size_t frame_index() const { return index_; }
  const Frame& frame() const { return frames_[index_]; }
  /// Each user's latest status report at or before time().
  Status status() const;
  /// The playback position.
  Timeline timeline() const;
  double peak_force_time() const { return peak_force_time_; }
  double largest_step_time() const { return largest_step_time_; }

  /// Play, pause, speed (> 0, else ignored), seek (clamped to the recording), jump.
  void command(const Command& command);
  /// Moves the position on by `wall_seconds` (> 0, else ignored) times the speed while playing;
  /// pauses at the end.
  void advance(double wall_seconds);
  /// Moves the position to `time`, clamped to the recording; NaN is ignored.
  void seek(double time);

 private:
  struct TimedStatus {
    double time = 0;
    UserStatus status;
  };

  Scene scene_;
  std::vector<Frame> frames_;
  std::vector<TimedStatus> statuses_;  // by time
  double time_ = 0, speed_ = 1;
  bool playing_ = false;
  std::size_t index_ = 0;
  double peak_force_time_ = 0, largest_step_time_ = 0;
};

}  // namespace cohaptic::view
