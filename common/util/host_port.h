// Parsing "HOST:PORT" from the command line.
#pragma once

#include <cstdint>
#include <string>

namespace cohaptic {

/// Splits `text` into host and port. Returns an empty string on success, otherwise what
/// was wrong. Port 0 (any free port) is accepted only if `allow_any_port`.
std::string parse_host_port(const std::string& text, std::string& host, std::uint16_t& port,
                            bool allow_any_port);

}  // namespace cohaptic
