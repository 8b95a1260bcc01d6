// Text from a peer (a user name, a header), made safe to log: one line, no terminal
// control. Printable means UTF-8 without control characters (C0, DEL, C1: a newline forges
// a log line, an escape sequence or C1's CSI drives a terminal).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace cohaptic {

/// The length of the UTF-8 sequence at `text[at]` if it is well formed and its code point is
/// not a control character; 0 otherwise.
std::size_t printable_sequence_at(std::string_view text, std::size_t at);

/// `text` with every byte that is not part of a printable sequence as \xNN, cut after
/// `max_bytes` with "...".
std::string printable(std::string_view text, std::size_t max_bytes = 64);

}  // namespace cohaptic
