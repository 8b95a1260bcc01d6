#include "common/mesh/mesh_with_gmsh.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "common/util/child_process.h"
#include "common/util/content_hash.h"
#include "common/util/error.h"
#include "common/util/stopwatch.h"

namespace cohaptic {
namespace {

constexpr auto kGmshTimeout = std::chrono::minutes(30);
constexpr std::size_t kOutputShown = 1500;  // characters of gmsh's output in an error

std::filesystem::path find_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream directories(path ? path : "");
  for (std::string directory; std::getline(directories, directory, ':');) {
    const std::filesystem::path candidate =
        std::filesystem::path(directory.empty() ? "." : directory) / program;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return {};
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(fmt::format("gmsh: cannot read the script {}", file.string()));
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Runs gmsh with `arguments` (output to `log`), waits; throws Error naming `what` on failure.
std::string run_gmsh(const std::filesystem::path& gmsh, const std::vector<std::string>& arguments,
                     const std::filesystem::path& log, const std::string& what) {
  ChildProcess process(gmsh.string(), arguments, log);
  const std::optional<int> status = process.wait(kGmshTimeout);
  std::string output = process.log_text();
  if (!status || *status != 0) {
    if (output.size() > kOutputShown) output = "..." + output.substr(output.size() - kOutputShown);
    throw Error(fmt::format("gmsh: {} {}:\n{}", what,
                            status ? fmt::format("failed (exit {})", *status) : "timed out",
                            output));
  }
  return output;
}

}  // namespace

std::filesystem::path mesh_with_gmsh(const GmshScript& script,
                                     const std::filesystem::path& cache_directory) {
  const std::filesystem::path gmsh = find_on_path("gmsh");
  if (gmsh.empty())
    throw Error(fmt::format(
        "gmsh: meshing {} needs the gmsh program, which is not on PATH (deploy/install-deps.sh "
        "installs it)",
        script.geo.string()));
  std::error_code error;
  std::filesystem::create_directories(cache_directory, error);
  if (error)
    throw Error(fmt::format("gmsh: cannot create the mesh cache {}: {}", cache_directory.string(),
                            error.message()));
  const std::filesystem::path log = cache_directory / fmt::format("gmsh.{}.log", ::getpid());
  const std::string version = run_gmsh(gmsh, {"--version"}, log, "--version");

  ContentHasher hasher;
  hasher.text(read_text(script.geo)).text(version);
  for (const auto& [name, value] : script.parameters) hasher.text(name).value(value);
  const std::filesystem::path mesh =
      cache_directory / (to_hex(hasher.finish()).substr(0, 32) + ".msh");
  if (std::filesystem::exists(mesh)) {
    std::filesystem::remove(log, error);
    return mesh;
  }

  std::string settings;
  std::vector<std::string> arguments = {script.geo.string(), "-3", "-nt", "1", "-v", "2"};
  for (const auto& [name, value] : script.parameters) {
    arguments.insert(arguments.end(), {"-setnumber", name, fmt::format("{:.17g}", value)});
    settings += fmt::format("{}{} = {:g}", settings.empty() ? "" : ", ", name, value);
  }
  // gmsh writes beside the final name; the rename makes the cached mesh appear whole.
  const std::filesystem::path partial =
      cache_directory / fmt::format("{}.{}.partial.msh", mesh.stem().string(), ::getpid());
  arguments.insert(arguments.end(), {"-o", partial.string()});
  spdlog::info("gmsh: meshing {}{} ...", script.geo.string(),
               settings.empty() ? "" : " (" + settings + ")");
  const Stopwatch watch;
  try {
    run_gmsh(gmsh, arguments, log, "meshing " + script.geo.string());
  } catch (const Error&) {
    std::filesystem::remove(partial, error);
    throw;
  }
  if (!std::filesystem::exists(partial))
    throw Error(fmt::format("gmsh: meshing {} wrote no mesh (is there a 3-D volume?)",
                            script.geo.string()));
  std::filesystem::rename(partial, mesh, error);
  if (error)
    throw Error(
        fmt::format("gmsh: cannot move the mesh into {}: {}", mesh.string(), error.message()));
  std::filesystem::remove(log, error);
  spdlog::info("gmsh: meshed in {:.1f} s, cached as {}", watch.elapsed_ms() / 1000, mesh.string());
  return mesh;
}

}  // namespace cohaptic
