// What the live view's server accepts from a browser, as plain functions over the bytes
// (view_server.cpp applies them; the fuzz target tests/fuzz/fuzz_view.cpp feeds them):
// the WebSocket handshake (the data path /ws, the token when one is required, no page from
// another origin) and the messages a browser sends (a binary view.proto Command with a
// body). Compiled into the C++17 web server too, so C++17 only here.
#pragma once

#include <optional>
#include <string>

#include "cohaptic/view.pb.h"

namespace cohaptic::view {

/// The value of `name` in a resource's query string ("/ws?token=abc" -> "abc"); empty if
/// absent.
std::string query_value(const std::string& resource, const std::string& name);

/// Whether a Host header ("localhost:8080", "127.0.0.1", "[::1]:80") names this machine
/// by a loopback address or "localhost".
bool names_this_machine(const std::string& host);

/// Why a WebSocket handshake for `resource` (path and query) with these Origin and Host
/// headers is refused when the view requires `token` (empty: none); empty if it is
/// accepted. Without a token the Host must name this machine (names_this_machine), so a
/// page on a name rebound to 127.0.0.1 cannot read the session. The token is compared in a
/// time that does not depend on where it differs.
std::string handshake_refusal(const std::string& resource, const std::string& origin,
                              const std::string& host, const std::string& token);

/// A browser's binary message as a Command; nothing unless it parses and has a body.
std::optional<Command> parse_command(const std::string& payload);

}  // namespace cohaptic::view
