// Meshing a Gmsh script (.geo) with the gmsh program, for a scene or a tool that says how
// its mesh is made instead of shipping it (a graded block is a few lines of script and
// several megabytes of mesh). gmsh runs once per script and setting: its mesh is kept in a
// cache directory, named by a hash of the script's bytes, the settings and gmsh's version,
// and written there whole or not at all. The mesh is gmsh's: units are the script's own.
#pragma once

#include <filesystem>
#include <map>
#include <string>

namespace cohaptic {

struct GmshScript {
  std::filesystem::path geo;                 ///< the script
  std::map<std::string, double> parameters;  ///< passed as -setnumber NAME VALUE
};

/// The 3-D mesh of `script` (.msh), made by gmsh (found on PATH) unless `cache_directory`
/// holds it already. Logs while gmsh runs (it may take seconds). Throws Error naming the
/// script if gmsh is missing, fails (with the end of its output) or writes no mesh.
std::filesystem::path mesh_with_gmsh(const GmshScript& script,
                                     const std::filesystem::path& cache_directory);

}  // namespace cohaptic
