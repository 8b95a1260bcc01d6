#include "proto/wire/user_name.h"

#include <fmt/format.h>

#include "common/util/printable.h"

namespace cohaptic::wire {

std::string user_name_problem(std::string_view name) {
  if (name.empty()) return "a user name is required";
  if (name.size() > kMaxUserNameBytes)
    return fmt::format("a user name is at most {} bytes (this one has {})", kMaxUserNameBytes,
                       name.size());
  for (std::size_t i = 0; i < name.size();) {
    const std::size_t length = printable_sequence_at(name, i);
    if (length == 0)
      return fmt::format(
          "a user name is UTF-8 text without control characters (byte {} is 0x{:02x})", i,
          static_cast<unsigned char>(name[i]));
    i += length;
  }
  return "";
}

}  // namespace cohaptic::wire
