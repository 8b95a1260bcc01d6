#include "common/scene/scene_files.h"

#include <fmt/format.h>

#include <system_error>

#include "common/util/regular_file.h"

namespace cohaptic {
namespace {

// Whether `path` is `folder` or inside it (both canonical: no "..", no links).
bool is_inside(const std::filesystem::path& path, const std::filesystem::path& folder) {
  const std::filesystem::path relative = path.lexically_relative(folder);
  return !relative.empty() && *relative.begin() != "..";
}

}  // namespace

std::filesystem::path SceneFiles::resolve(const YamlCursor& at, const std::string& what) const {
  std::filesystem::path resolved = at.text();
  if (resolved.is_relative()) resolved = dir / resolved;
  if (access.confined_to) {
    std::error_code error;
    const std::filesystem::path real = std::filesystem::weakly_canonical(resolved, error);
    const std::filesystem::path folder =
        std::filesystem::weakly_canonical(*access.confined_to, error);
    if (error || !is_inside(real, folder))
      at.fail_message(
          fmt::format("{} {} is outside {}, the only folder this scene's files may be read from",
                      what, resolved.string(), access.confined_to->string()));
  }
  if (const auto why = why_not_a_regular_file(resolved))
    at.fail_message(fmt::format("{} {} {}", what, resolved.string(), *why));
  return resolved;
}

void SceneFiles::require_gmsh_allowed(const YamlCursor& at) const {
  if (!access.gmsh_scripts)
    at.fail_message(
        "a gmsh script, and gmsh reads whatever its script names: here only mesh files, surfaces "
        "and boxes "
        "are allowed");
}

}  // namespace cohaptic
