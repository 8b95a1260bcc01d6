#include "view/live_view.h"

#include <spdlog/spdlog.h>

#include "common/util/monotonic_clock.h"
#include "proto/wire/header.h"
#include "view/view_token.h"

namespace cohaptic::view {

LiveView::LiveView(const Model& model, std::span<ComplianceColumns* const> columns,
                   wire::Protocol protocol, const record::InjectedDelays& injected,
                   LiveViewOptions options, record::SessionRecorder* recorder)
    : shown_(shown_scene(model, columns)),
      recorder_(recorder),
      period_ns_(static_cast<std::int64_t>(1e9 / options.rate_hz)),
      server_({options.host, options.port, access_token(options.host, options.token_file),
               options.assets, options.proto}) {
  const Scene scene = view_scene(model, shown_, protocol, injected, options.rate_hz, "live");
  if (recorder_) recorder_->view_scene(monotonic_now_ns(), scene);
  server_.publish(Channel::scene, server_message(scene));
}

void LiveView::publish_frame(std::int64_t now_ns, double time, FrameState state,
                             std::uint64_t steps) {
  const double interval_s = static_cast<double>(now_ns - last_frame_ns_) * 1e-9;
  const double rate = last_frame_ns_ > 0 && interval_s > 0
                          ? static_cast<double>(steps - last_steps_) / interval_s
                          : 0.0;
  last_frame_ns_ = now_ns;
  last_steps_ = steps;
  next_frame_ns_ += period_ns_;
  if (next_frame_ns_ <= now_ns) next_frame_ns_ = now_ns + period_ns_;
  bool waiting = false;
  {
    std::lock_guard lock(pending_mutex_);
    waiting = pending_.has_value();
    pending_ = PendingFrame{now_ns, time, rate, std::move(state)};
  }
  if (!waiting)
    server_.post([this] { build_frame(); });  // else the build already posted takes this state
}

void LiveView::build_frame() {
  std::optional<PendingFrame> taken;
  {
    std::lock_guard lock(pending_mutex_);
    taken.swap(pending_);
  }
  if (!taken) return;
  Frame frame = view_frame(taken->state, shown_, sequence_ + 1, taken->time, taken->sim_rate_hz);
  ++sequence_;
  if (recorder_) recorder_->view_frame(taken->time_ns, frame);
  server_.publish(Channel::frame, server_message(std::move(frame)));
}

void LiveView::publish_status(int slot, const std::string& user, const wire::ClientStatus& status,
                              double time) {
  UserStatus& entry = statuses_[slot];
  entry.set_slot(static_cast<std::uint32_t>(slot));
  entry.set_user(user);
  *entry.mutable_figures() = status;
  entry.set_received_time(time);
  Status message;
  for (const auto& [_, each] : statuses_) *message.add_users() = each;
  server_.publish(Channel::status, server_message(std::move(message)));
}

}  // namespace cohaptic::view
