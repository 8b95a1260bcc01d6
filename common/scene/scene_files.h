// The files a scene names (mesh files, gmsh scripts, surfaces): how a name is resolved and
// which files may be read. A relative name is resolved against the scene file's folder.
// A scene that came with a recording is confined: a file outside `confined_to` (after
// "..", and symbolic links, are resolved) is refused before it is opened, and the error
// names the file and the folder, never anything in the file. Gmsh scripts are refused
// unless allowed: gmsh reads whatever its script names, wherever it is.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "common/util/yaml_cursor.h"

namespace cohaptic {

/// Which of the files a scene names may be read. The default: any, gmsh scripts included.
struct SceneFileAccess {
  std::optional<std::filesystem::path> confined_to;  ///< nullopt: anywhere
  bool gmsh_scripts = true;
};

/// How one scene's files are found: its folder, and the access it was given.
struct SceneFiles {
  std::filesystem::path dir;
  SceneFileAccess access;

  /// The file `at` names, resolved; fails at `at` (naming `what`, e.g. "mesh file") unless
  /// it is a regular file that the access allows.
  std::filesystem::path resolve(const YamlCursor& at, const std::string& what) const;
  /// Fails at `at` unless gmsh scripts are allowed.
  void require_gmsh_allowed(const YamlCursor& at) const;
};

}  // namespace cohaptic
