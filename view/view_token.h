// Who may watch: the live view is bound to loopback unless told otherwise, and on any other
// address a browser must present a token (docs/live-view.md, "The live view"). The token comes
// from a file (first line, at least 16 characters) or is drawn at random and printed in
// the page's address.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace cohaptic::view {

/// True for 127.0.0.0/8 and ::1 (a numeric address; names are not resolved).
bool is_loopback(const std::string& host);

/// A new random token: 32 hexadecimal characters (128 bits).
std::string random_token();

/// The token a view on `host` requires: the file's when given (Error if it cannot be read
/// or is shorter than 16 characters), else none on loopback and a random one elsewhere.
std::string access_token(const std::string& host,
                         const std::optional<std::filesystem::path>& token_file);

}  // namespace cohaptic::view
