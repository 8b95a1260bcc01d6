#include "support/process.h"

#include <gtest/gtest.h>
#include <unistd.h>

namespace cohaptic::testing {

std::filesystem::path scratch_directory(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) /
                                    ("cohaptic-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string server_program() { return std::string(COHAPTIC_BINARY_DIR) + "/server/cohaptic-server"; }
std::string client_program() { return std::string(COHAPTIC_BINARY_DIR) + "/client/cohaptic-client"; }

}  // namespace cohaptic::testing
