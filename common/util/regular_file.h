// Whether a path a user wrote (in a scene or a study file) names a file that can be read,
// and if not, why, in words for an error message. Never throws: a name the system refuses
// outright (too long, say) is a reason like any other, where std::filesystem::exists()
// would throw.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace cohaptic {

/// nullopt if `path` is a regular file (or a link to one); otherwise "does not exist",
/// "is a directory", "is not a regular file", or the system's reason, e.g. "cannot be
/// examined: File name too long".
std::optional<std::string> why_not_a_regular_file(const std::filesystem::path& path);

}  // namespace cohaptic
