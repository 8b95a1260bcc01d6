// Fuzz target: the live view's input (view/): a recording replayed into the page
// (read_recording, then view::ReplayPlayer over its view scene, frames and status reports),
// the Commands browsers send (parse_command, then the player) and the WebSocket handshake
// (handshake_refusal).
//
// Input: pieces (fuzz_support.h). The first is a recording file; each further piece, by its
// kind modulo 3: 0 a browser's message, 1 wall time passing (the first 8 bytes as a double,
// seconds), 2 a handshake's resource (path and query) against a required token.
// Properties:
//   - the recording is read or refused with cohaptic::Error (so is one without view frames);
//   - after every command and every advance the player's position lies in the recording's
//     [start, end], on the last frame at or before it, at a speed in (0, 100], and the
//     status it reports was received by then; jumps land in [start, end];
//   - a handshake is accepted exactly when its path is /ws and its query's token is the
//     required one.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>

#include "common/util/error.h"
#include "proto/record/recording.h"
#include "tests/fuzz/fuzz_support.h"
#include "view/browser_input.h"
#include "view/replay_player.h"

namespace {

using namespace cohaptic;
using fuzz::require;

std::string text_of(std::span<const std::uint8_t> bytes) {
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

void require_consistent(const view::ReplayPlayer& player) {
  const view::Timeline timeline = player.timeline();
  if (!std::isfinite(timeline.start()) || !std::isfinite(timeline.end()))
    return;  // checked where frames are read
  require(timeline.start() <= timeline.time() && timeline.time() <= timeline.end(),
          "the position lies in the recording");
  require(player.frame().time() <= timeline.time() || player.frame_index() == 0,
          "the frame shown is at or before the position");
  require(timeline.speed() > 0 && timeline.speed() <= 100, "the speed is in (0, 100]");
  for (double jump : {timeline.peak_force_time(), timeline.largest_step_time()})
    require(timeline.start() <= jump && jump <= timeline.end(), "a jump lands in the recording");
  const view::Status shown = player.status();
  for (const view::UserStatus& status : shown.users())
    require(status.received_time() <= timeline.time(),
            "the status shown was received by the position");
}

void check_handshake(const std::string& resource) {
  static const std::string token = "fuzz-token-0123456789";
  const bool accepted = view::handshake_refusal(resource, "", "localhost:8080", token).empty();
  const bool right = resource.substr(0, resource.find('?')) == "/ws" &&
                     view::query_value(resource, "token") == token;
  require(accepted == right, "a handshake is accepted exactly with the path /ws and the token");
  require(!view::handshake_refusal(resource, "http://evil.example", "localhost:8080", "").empty(),
          "a page from another origin is refused");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::vector<fuzz::Piece> pieces = fuzz::split_pieces({data, size});
  if (pieces.empty()) return 0;
  std::optional<view::ReplayPlayer> player;
  try {
    player.emplace(record::read_recording(fuzz::scratch_file(pieces.front().bytes, ".mcap")));
  } catch (const Error&) {
  }
  if (player) require_consistent(*player);
  for (std::size_t i = 1; i < pieces.size(); ++i) {
    const fuzz::Piece& piece = pieces[i];
    switch (piece.kind % 3) {
      case 0:
        if (const std::optional<view::Command> command = view::parse_command(text_of(piece.bytes));
            command && player)
          player->command(*command);
        break;
      case 1:
        if (player && piece.bytes.size() >= sizeof(double)) {
          double seconds = 0;
          std::memcpy(&seconds, piece.bytes.data(), sizeof seconds);
          player->advance(seconds);
        }
        break;
      default:
        check_handshake(text_of(piece.bytes));
        break;
    }
    if (player) require_consistent(*player);
  }
  return 0;
}
