// ViewServer: the web server of the live view (docs/live-view.md, "The live view"), and of a
// study's rating page (lab/rating_page.h). On its own thread and io_context it serves, on
// one TCP port:
//   - HTTP GET of the page and its assets (view_assets.h), held in memory;
//   - a WebSocket at /ws for the data: binary view.proto ServerMessages out, Commands in.
// Data is published per Channel, newest wins: publish() keeps only the newest message of
// each channel (one pointer swap under a mutex, from any thread, never waiting on a
// browser) and wakes the server's thread, which sends each browser the newest message of
// every channel it has not had yet, the scene first (the rating page's one message is its
// scene). A browser with more than
// max_buffered_bytes still waiting to leave gets nothing new until it has caught up: its
// frames are dropped (counted), never queued without bound. Each message is framed once and
// the same buffer queued for every browser. An accept() that fails (out of file
// descriptors) is tried again after a pause, never in a spin.
// Safety: a non-empty token must be given as /ws?token=... or the handshake is refused
// (403); a handshake from another web page (its Origin not this server) is refused too, and
// without a token so is one whose Host does not name this machine (browser_input.h). Only
// GET is served, and no request may carry a body (413, before it is read); at most
// max_browsers are connected at once (503 beyond).
// A browser's message longer than max_command_bytes, not binary, or not a view Command
// closes that browser's connection and nothing else.
// Built on websocketpp over standalone asio; this header exposes neither (its translation
// unit is C++17, see view/CMakeLists.txt).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "view/view_assets.h"

namespace cohaptic::view {

class Command;

struct ViewServerOptions {
  std::string host = "127.0.0.1";
  std::uint16_t port = 0;        ///< 0: any free port
  std::string token;             ///< required on the WebSocket when not empty
  std::filesystem::path assets;  ///< view/web, with its libraries in lib/ (view_assets.h)
  std::filesystem::path proto;   ///< the proto/ directory (the page decodes its view.proto)
  std::size_t max_command_bytes = 1024;
  int max_browsers = 64;  ///< connected at once; beyond, a handshake is refused (503)
  std::size_t max_buffered_bytes = 2u << 20;  ///< per browser: beyond this, new frames are dropped
  ViewPage page = ViewPage::live_view;        ///< the page served at "/" (and what it needs)
};

/// The kinds of message a browser gets, in the order it gets them.
enum class Channel : std::size_t { scene, frame, status, timeline };
inline constexpr std::size_t kChannels = 4;

struct ViewCounters {
  int browsers = 0;               ///< connected now
  std::uint64_t connections = 0;  ///< WebSocket connections opened, in all
  std::uint64_t refused = 0;      ///< handshakes refused (token, origin, path)
  std::uint64_t closed_for_bad_message = 0;
  std::uint64_t messages_sent = 0, bytes_sent = 0;
  std::uint64_t dropped = 0;  ///< messages superseded before a slow browser got them
  std::uint64_t accept_errors =
      0;  ///< accept() failed (out of file descriptors, say): tried again later
  std::uint64_t http_requests = 0;
};

class ViewServer {
 public:
  /// Called on the server's thread for every valid Command a browser sends.
  using CommandHandler = std::function<void(const Command&)>;

  /// Loads the assets and binds the port. Throws Error naming a missing asset (and how to
  /// install it) or the address that cannot be bound.
  explicit ViewServer(ViewServerOptions options, CommandHandler on_command = {});
  ~ViewServer();  ///< stop()
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;

  /// Starts the server's thread.
  void start();
  /// Closes every connection and ends the thread. Idempotent.
  void stop();

  std::uint16_t port() const;
  /// The page's address, with the token when there is one and `with_token` (a token the
  /// operator gave in a file is not for the logs).
  std::string url(bool with_token = true) const;

  /// Makes `message` (a serialized ServerMessage) the newest of `channel`. Any thread.
  void publish(Channel channel, std::string message);
  /// Any thread.
  ViewCounters counters() const;
  /// Whether a browser is connected now (any thread; one atomic load).
  bool watched() const;
  /// Runs `task` on the server's thread, after what is queued there (any thread). Tasks
  /// still queued when the server stops are dropped.
  void post(std::function<void()> task);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cohaptic::view
