#include "lab/replay_view.h"

#include <signal.h>
#include <spdlog/spdlog.h>
#include <time.h>

#include <chrono>
#include <mutex>

#include "view/live_view.h"
#include "view/replay_player.h"
#include "view/view_token.h"

namespace cohaptic {
namespace {

constexpr double kTickRate_hz = 30;

}  // namespace

int serve_replay(const record::Recording& recording, const ReplayViewOptions& options) {
  view::ReplayPlayer player(recording);
  std::mutex mutex;  // the player: commands on the view server's thread, playback here
  // Signals are taken here, synchronously: blocked before the view server's thread starts
  // (it inherits the mask), then waited for between ticks.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  view::ViewServerOptions settings;
  settings.host = options.host;
  settings.port = options.port;
  settings.token = view::access_token(options.host, options.token_file);
  settings.assets = COHAPTIC_VIEW_WEB_DIR;
  settings.proto = COHAPTIC_PROTO_DIR;
  std::uint64_t commands = 0;
  view::ViewServer server(settings, [&](const view::Command& command) {
    std::lock_guard lock(mutex);
    player.command(command);
    ++commands;
  });
  server.publish(view::Channel::scene, view::server_message(player.scene()));
  server.start();
  spdlog::info(
      "replay of {} ({} frames, {:.1f} s) in the live view at {}{}", recording.file.string(),
      recording.view_frames.size(), player.timeline().end() - player.timeline().start(),
      server.url(!options.token_file),  // a token from a file stays out of the log
      options.token_file ? " (add ?token= and the token in " + options.token_file->string() + ")"
                         : "");

  std::size_t shown = static_cast<std::size_t>(-1);
  std::uint64_t handled = 0, shown_timeline = 0;
  bool was_playing = false;
  auto last = std::chrono::steady_clock::now();
  const timespec tick{0, static_cast<long>(1e9 / kTickRate_hz)};
  for (;;) {
    const int signal = sigtimedwait(&stop_signals, nullptr, &tick);
    if (signal == SIGINT || signal == SIGTERM) break;
    const auto now = std::chrono::steady_clock::now();
    std::lock_guard lock(mutex);
    player.advance(std::chrono::duration<double>(now - last).count());
    last = now;
    // A browser that connects later gets every channel's newest message.
    if (player.frame_index() != shown) {
      shown = player.frame_index();
      server.publish(view::Channel::frame, view::server_message(player.frame()));
      server.publish(view::Channel::status, view::server_message(player.status()));
    }
    if (shown_timeline == 0 || player.playing() || was_playing || commands != handled) {
      server.publish(view::Channel::timeline, view::server_message(player.timeline()));
      ++shown_timeline;
    }
    handled = commands;
    was_playing = player.playing();
  }
  spdlog::info("replay view stopped");
  server.stop();
  return 0;
}

}  // namespace cohaptic
