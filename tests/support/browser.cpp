#include "support/browser.h"

#include <cstdlib>
#include <filesystem>
#include <sstream>

namespace cohaptic::testing {

namespace fs = std::filesystem;

std::string node_program() {
  const char* path = std::getenv("PATH");
  std::stringstream directories(path ? path : "");
  for (std::string directory; std::getline(directories, directory, ':');)
    if (fs::exists(fs::path(directory) / "node")) return (fs::path(directory) / "node").string();
  return "";
}

std::string missing_browser() {
  const char* chosen = std::getenv("CHROMIUM");
  const bool chromium = (chosen && fs::exists(chosen)) || fs::exists("/usr/bin/chromium") ||
                        fs::exists("/usr/bin/chromium-browser");
  if (node_program().empty())
    return "no node on the PATH: install Node.js (deploy/install-deps.sh does)";
  if (!chromium)
    return "no Chromium: install the Debian package chromium (deploy/install-deps.sh does)";
  if (!fs::exists(fs::path(COHAPTIC_SOURCE_DIR) / "deploy/node/node_modules/playwright-core"))
    return "no playwright-core in deploy/node/node_modules: run deploy/install-deps.sh (npm ci "
           "--prefix deploy/node)";
  return "";
}

}  // namespace cohaptic::testing
