// Browsers without a browser, for the view server's tests and benchmark: a WebSocket client
// (websocketpp, on its own thread) that keeps what it receives and how its connection
// ended; a "stalled" browser that opens a WebSocket and then never reads; and a plain HTTP
// GET. Compiled as C++17 like the server's websocketpp unit (tests/CMakeLists.txt); no
// websocketpp type crosses this header.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace cohaptic::testing {

class WebSocketClient {
 public:
  /// Connects to `url` (ws://HOST:PORT/PATH?QUERY), sending `origin` as the Origin header
  /// when not empty. Returns at once; see wait_open().
  explicit WebSocketClient(const std::string& url, const std::string& origin = "");
  ~WebSocketClient();
  WebSocketClient(const WebSocketClient&) = delete;
  WebSocketClient& operator=(const WebSocketClient&) = delete;

  /// Waits until the handshake succeeded (true) or failed or the connection closed (false).
  bool wait_open(std::chrono::milliseconds timeout);
  /// Waits until the connection is closed (by either side); false on timeout.
  bool wait_closed(std::chrono::milliseconds timeout);
  /// Waits until at least `count` messages have arrived; false on timeout.
  bool wait_messages(std::size_t count, std::chrono::milliseconds timeout);

  void send_binary(const std::string& payload);
  void send_text(const std::string& payload);

  /// The binary messages received so far (a copy).
  std::vector<std::string> messages() const;
  std::size_t message_count() const;
  /// The last message received (kept even with count_only()); empty before the first.
  std::string last_message() const;
  std::uint64_t bytes_received() const;
  /// The HTTP status of a refused handshake (0 if none), and the close code the server sent
  /// (0 while open or if it never closed).
  int refused_status() const;
  int close_code() const;
  /// Keep only counts (not the messages) from now on: for the benchmark's many browsers.
  void count_only();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A browser that completes the WebSocket handshake on `host`:`port` at /ws and then does not
/// read until told to: the server's sends pile up in the socket until it stops sending to it.
class StalledWebSocket {
 public:
  StalledWebSocket(const std::string& host, std::uint16_t port);
  ~StalledWebSocket();
  /// Whether the server answered the handshake with 101.
  bool upgraded() const { return upgraded_; }
  /// Reads at last: the server's frames, until one whose payload is `wanted` (true), or the
  /// connection ends or `timeout` passes first (false).
  bool read_until_message(const std::string& wanted, std::chrono::milliseconds timeout);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  bool upgraded_ = false;
};

/// GET `path` from `host`:`port`; the whole response (status line, headers, body).
std::string http_get(const std::string& host, std::uint16_t port, const std::string& path);
/// Sends `request` (a whole HTTP request, as is) to host:port; the response to the server's
/// close, or with `head_only` its status line and headers (an upgrade keeps the connection).
std::string http_exchange(const std::string& host, std::uint16_t port, const std::string& request,
                          bool head_only = false);

}  // namespace cohaptic::testing
