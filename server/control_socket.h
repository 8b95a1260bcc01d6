// ControlSocket: the experimenter's line into a running server (`--control PATH`): a
// Unix-domain stream socket, readable and writable by the server's user only, that takes one
// JSON object per line and answers each with one line:
//   {"serve": "B"}   switch to condition B (served_conditions.h)
//                    -> {"served": "B", "switches": 3, "time_s": 12.345}
//   {"serve_next": true}  switch to the condition after the one served now (a device button's
//                    switch: served_conditions.h) -> as for "serve"
//   {"status": true} -> {"served": "A", "switches": 2, "time_s": 20.1}
// Anything else (malformed JSON, an unknown command or condition) gets {"error": "..."}
// naming what was wrong and the connection stays open; a line over 4 KiB gets that answer
// and the connection is closed (its end cannot be found). The session goes on either way.
// Runs on the server's I/O thread (the handler too); the socket file is removed on close.
#pragma once

#include <asio.hpp>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

namespace cohaptic {

class ControlSocket {
 public:
  /// Answers one command (already parsed); throws Error for one it cannot do.
  using Handler = std::function<nlohmann::json(const nlohmann::json& command)>;

  /// Binds `path` (a stale socket file there is replaced; another kind of file is an Error)
  /// and starts accepting.
  ControlSocket(asio::io_context& io, std::filesystem::path path, Handler handler);
  ~ControlSocket();
  ControlSocket(const ControlSocket&) = delete;
  ControlSocket& operator=(const ControlSocket&) = delete;

  /// Stops accepting, closes every connection and removes the socket file. On the I/O thread.
  void close();

 private:
  class Connection;
  void accept();

  std::filesystem::path path_;
  std::shared_ptr<const Handler> handler_;
  asio::local::stream_protocol::acceptor acceptor_;
  std::vector<std::weak_ptr<Connection>> connections_;
};

}  // namespace cohaptic
