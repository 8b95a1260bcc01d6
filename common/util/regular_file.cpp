#include "common/util/regular_file.h"

#include <system_error>

namespace cohaptic {

std::optional<std::string> why_not_a_regular_file(const std::filesystem::path& path) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (status.type() == std::filesystem::file_type::not_found) return "does not exist";
  if (error) return "cannot be examined: " + error.message();
  if (status.type() == std::filesystem::file_type::directory) return "is a directory";
  if (status.type() != std::filesystem::file_type::regular) return "is not a regular file";
  return std::nullopt;
}

}  // namespace cohaptic
