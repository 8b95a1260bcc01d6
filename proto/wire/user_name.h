// A user's name as a Join carries it: shown to the other users, written to logs, reports
// and recordings. Names are 1 to kMaxUserNameBytes bytes of UTF-8 without control
// characters (C0, DEL, C1: a newline forges a log line, an escape sequence drives a
// terminal), so whatever a peer sends, what is logged is one line of its own.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace cohaptic::wire {

inline constexpr std::size_t kMaxUserNameBytes = 64;

/// Why `name` is not a user name, or empty if it is one.
std::string user_name_problem(std::string_view name);

/// `text` (a peer's, untrusted) safe to log on one line: control characters and bytes that
/// are not UTF-8 as \xNN, cut after `max_bytes` with "...".
std::string printable(std::string_view text, std::size_t max_bytes = kMaxUserNameBytes);

}  // namespace cohaptic::wire
