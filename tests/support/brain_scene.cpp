#include "support/brain_scene.h"

#include <fstream>
#include <regex>
#include <sstream>

#include "common/scene/load_scene.h"
#include "common/util/error.h"

namespace cohaptic::testing {
namespace {

const std::filesystem::path kBrainScene =
    std::filesystem::path(COHAPTIC_SOURCE_DIR) / "scenes" / "brain.yaml";

}  // namespace

std::string brain_scene_text(const std::string& mesh) {
  std::stringstream text;
  text << std::ifstream(kBrainScene).rdbuf();
  const std::string brain_directory = (kBrainScene.parent_path() / "brain").string() + "/";
  const std::regex mesh_line(R"(file: brain/\S+\.msh)");
  if (!std::regex_search(text.str(), mesh_line))
    throw Error(kBrainScene.string() + ": no mesh file under brain/ to replace");
  const std::string with_mesh = std::regex_replace(text.str(), mesh_line, "file: brain/" + mesh);
  return std::regex_replace(with_mesh, std::regex(R"(((file|surface): )brain/)"),
                            "$1" + brain_directory);
}

Scene brain_scene(const std::string& mesh) {
  return parse_scene(brain_scene_text(mesh), kBrainScene);
}

std::filesystem::path write_brain_scene(const std::filesystem::path& directory,
                                        const std::string& mesh) {
  const std::filesystem::path file = directory / "brain.yaml";
  std::ofstream(file) << brain_scene_text(mesh);
  return file;
}

}  // namespace cohaptic::testing
