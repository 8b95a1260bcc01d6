// RatingPage: the page on which a subject of a study rated by people (lab/person_pairs.h)
// switches between a pair's two conditions and rates it, in a browser: on a tablet in the
// subject's free hand, or on the experimenter's screen. Served by a view server of its own
// (view/view_server.h: same port rules, token off loopback, Origin check, message limits) at
// `cohaptic-lab study ... --rating-page HOST:PORT`. The page shows one RatingScreen
// (view.proto), sent whole on each change; each RatingAction a browser sends becomes the
// terminal command it stands for ("s", "+1", "y", "n", "q"), so one parser takes both.
// Any number of browsers may be open; they see the same screen and their actions interleave.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "cohaptic/view.pb.h"

namespace cohaptic {
namespace view {
class ViewServer;
}

class RatingPage {
 public:
  /// Binds HOST:PORT (port 0: any free port) and starts serving. Throws Error when the page's
  /// files are missing or the address cannot be bound.
  RatingPage(const std::string& host, std::uint16_t port);
  ~RatingPage();
  RatingPage(const RatingPage&) = delete;
  RatingPage& operator=(const RatingPage&) = delete;

  /// The page's address (with its token off loopback).
  std::string url() const;
  /// Makes `screen` what every browser shows. Any thread.
  void show(const view::RatingScreen& screen);
  /// The next action of any browser, as its terminal command; nothing if none came within
  /// `timeout`.
  std::optional<std::string> next_command(std::chrono::milliseconds timeout);

 private:
  void received(const view::Command& command);

  std::mutex mutex_;
  std::condition_variable arrived_;
  std::deque<std::string> commands_;
  std::unique_ptr<view::ViewServer> server_;
};

/// The terminal command a rating action stands for; nothing for an action with no body.
std::optional<std::string> command_of(const view::RatingAction& action);

}  // namespace cohaptic
