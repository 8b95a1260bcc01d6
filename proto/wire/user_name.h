// A user's name as a Join carries it: shown to the other users, written to logs, reports
// and recordings. Names are 1 to kMaxUserNameBytes bytes of printable UTF-8
// (common/util/printable.h), so whatever a peer sends, what is logged is one line of its own.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace cohaptic::wire {

inline constexpr std::size_t kMaxUserNameBytes = 64;

/// Why `name` is not a user name, or empty if it is one.
std::string user_name_problem(std::string_view name);

}  // namespace cohaptic::wire
