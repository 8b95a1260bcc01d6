#include "support/shipped_scenes.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "support/test_meshes.h"

namespace cohaptic::testing {

std::vector<std::string> scenes_with_surgeons() {
  namespace fs = std::filesystem;
  const fs::path scenes = source_path("scenes");
  std::vector<std::string> found;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(scenes)) {
    if (entry.path().filename() != "surgeon_a.yaml") continue;
    const fs::path dir = entry.path().parent_path();
    if (fs::exists(dir / "surgeon_b.yaml") && fs::exists(fs::path(dir.string() + ".yaml")))
      found.push_back(fs::relative(dir, scenes).generic_string());
  }
  std::sort(found.begin(), found.end());
  return found;
}

std::string scene_test_name(const std::string& scene) {
  std::string name = scene;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

}  // namespace cohaptic::testing
