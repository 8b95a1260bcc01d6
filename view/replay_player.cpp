#include "view/replay_player.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "common/util/error.h"

namespace cohaptic::view {
namespace {

double force_norm(const UserFrame& user) {
  if (!user.present() || user.force_size() != 3) return 0;
  return std::hypot(user.force(0), user.force(1), user.force(2));
}

// |F_now - F_before| of one user between two frames; 0 unless present in both.
double force_step(const UserFrame& now, const UserFrame& before) {
  if (!now.present() || !before.present() || now.force_size() != 3 || before.force_size() != 3)
    return 0;
  return std::hypot(now.force(0) - before.force(0), now.force(1) - before.force(1),
                    now.force(2) - before.force(2));
}

}  // namespace

ReplayPlayer::ReplayPlayer(const record::Recording& recording)
    : frames_(recording.view_frames.begin(), recording.view_frames.end()) {
  if (frames_.empty() || recording.view_scenes.empty())
    throw Error(fmt::format(
        "{}: no view frames in this recording: record the session with cohaptic-server --record "
        "and --view to replay it in the browser",
        recording.file.string()));
  std::stable_sort(frames_.begin(), frames_.end(),
                   [](const Frame& a, const Frame& b) { return a.time() < b.time(); });
  scene_ = recording.view_scenes.front();
  scene_.set_source(recording.file.filename().string());
  for (const Tool& tool : scene_.tools()) {
    ForceSeries* series = scene_.add_force_series();
    series->set_slot(tool.slot());
    for (const Frame& frame : frames_)
      for (const UserFrame& user : frame.users())
        if (user.slot() == tool.slot()) {
          series->add_times(frame.time());
          series->add_magnitudes(static_cast<float>(force_norm(user)));
        }
  }
  const std::int64_t zero = recording.config.start_time_ns();
  for (const record::ReceivedClientStatus& received : recording.client_statuses) {
    TimedStatus& entry = statuses_.emplace_back();
    entry.time = static_cast<double>(received.receive_time_ns() - zero) * 1e-9;
    entry.status.set_slot(received.slot());
    entry.status.set_user(received.user());
    *entry.status.mutable_figures() = received.status();
    entry.status.set_received_time(entry.time);
  }
  std::stable_sort(statuses_.begin(), statuses_.end(),
                   [](const auto& a, const auto& b) { return a.time < b.time; });

  // A recording without forces (or with none finite) jumps to its start, never outside it.
  peak_force_time_ = largest_step_time_ = frames_.front().time();
  double peak = -1, largest_step = -1;
  for (std::size_t k = 0; k < frames_.size(); ++k)
    for (int u = 0; u < frames_[k].users_size(); ++u) {
      const UserFrame& user = frames_[k].users(u);
      if (force_norm(user) > peak) {
        peak = force_norm(user);
        peak_force_time_ = frames_[k].time();
      }
      if (k == 0 || u >= frames_[k - 1].users_size()) continue;
      if (const double step = force_step(user, frames_[k - 1].users(u)); step > largest_step) {
        largest_step = step;
        largest_step_time_ = frames_[k].time();
      }
    }
  seek(frames_.front().time());
}

Status ReplayPlayer::status() const {
  std::map<std::uint32_t, const UserStatus*> latest;
  for (const TimedStatus& entry : statuses_) {
    if (entry.time > time_) break;
    latest[entry.status.slot()] = &entry.status;
  }
  Status status;
  for (const auto& [_, each] : latest) *status.add_users() = *each;
  return status;
}

Timeline ReplayPlayer::timeline() const {
  Timeline timeline;
  timeline.set_start(frames_.front().time());
  timeline.set_end(frames_.back().time());
  timeline.set_time(time_);
  timeline.set_playing(playing_);
  timeline.set_speed(speed_);
  timeline.set_peak_force_time(peak_force_time_);
  timeline.set_largest_step_time(largest_step_time_);
  return timeline;
}

void ReplayPlayer::command(const Command& command) {
  switch (command.body_case()) {
    case Command::kPlay:
      if (index_ + 1 >= frames_.size()) seek(frames_.front().time());  // at the end: from the start
      playing_ = true;
      break;
    case Command::kPause:
      playing_ = false;
      break;
    case Command::kSpeed:
      if (std::isfinite(command.speed()) && command.speed() > 0)
        speed_ = std::min(command.speed(), 100.0);
      break;
    case Command::kSeek:
      if (std::isfinite(command.seek())) seek(command.seek());
      break;
    case Command::kJump:
      if (command.jump() == Command::PEAK_FORCE)
        seek(peak_force_time_);
      else if (command.jump() == Command::LARGEST_STEP)
        seek(largest_step_time_);
      playing_ = false;
      break;
    case Command::kRating:  // the rating page's
    case Command::BODY_NOT_SET:
      break;
  }
}

void ReplayPlayer::advance(double wall_seconds) {
  if (!playing_ || !(wall_seconds > 0)) return;  // time never runs back, nor by NaN
  seek(time_ + wall_seconds * speed_);
  if (time_ >= frames_.back().time()) playing_ = false;
}

void ReplayPlayer::seek(double time) {
  if (std::isnan(time)) return;  // std::clamp would pass it through
  time_ = std::clamp(time, frames_.front().time(), frames_.back().time());
  const auto after =
      std::upper_bound(frames_.begin(), frames_.end(), time_,
                       [](double t, const Frame& frame) { return t < frame.time(); });
  index_ = static_cast<std::size_t>(std::max<std::ptrdiff_t>(after - frames_.begin() - 1, 0));
}

}  // namespace cohaptic::view
