#include "lab/rating_page.h"

#include <fmt/format.h>

#include "view/view_server.h"
#include "view/view_token.h"

namespace cohaptic {

std::optional<std::string> command_of(const view::RatingAction& action) {
  switch (action.action_case()) {
    case view::RatingAction::kSwitchCondition:
      return "s";
    case view::RatingAction::kChoose:
      return fmt::format("{:+d}", action.choose());
    case view::RatingAction::kConfirm:
      return "y";
    case view::RatingAction::kNext:
      return "n";
    case view::RatingAction::kStop:
      return "q";
    case view::RatingAction::ACTION_NOT_SET:
      break;
  }
  return std::nullopt;
}

RatingPage::RatingPage(const std::string& host, std::uint16_t port) {
  view::ViewServerOptions options;
  options.host = host;
  options.port = port;
  options.token = view::access_token(host, std::nullopt);
  options.assets = COHAPTIC_VIEW_WEB_DIR;
  options.proto = COHAPTIC_PROTO_DIR;
  options.page = view::ViewPage::rating;
  server_ = std::make_unique<view::ViewServer>(
      options, [this](const view::Command& command) { received(command); });
  server_->start();
}

RatingPage::~RatingPage() = default;  // the server first: its thread calls received()

std::string RatingPage::url() const { return server_->url(); }

void RatingPage::show(const view::RatingScreen& screen) {
  view::ServerMessage message;
  *message.mutable_rating() = screen;
  server_->publish(view::Channel::scene, message.SerializeAsString());
}

std::optional<std::string> RatingPage::next_command(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  if (!arrived_.wait_for(lock, timeout, [this] { return !commands_.empty(); })) return std::nullopt;
  std::string command = std::move(commands_.front());
  commands_.pop_front();
  return command;
}

void RatingPage::received(const view::Command& command) {
  if (!command.has_rating()) return;  // a live view's command: nothing to do here
  const std::optional<std::string> line = command_of(command.rating());
  if (!line) return;
  {
    std::lock_guard lock(mutex_);
    commands_.push_back(*line);
  }
  arrived_.notify_one();
}

}  // namespace cohaptic
