// A directory of the running test's own under the system's temporary directory, made on
// construction and removed with everything in it on destruction.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace cohaptic::testing {

struct ScratchDirectory {
  std::filesystem::path path = std::filesystem::temp_directory_path() /
                               ("cohaptic-test-" + std::to_string(::getpid()) + "-" +
                                ::testing::UnitTest::GetInstance()->current_test_info()->name());
  ScratchDirectory() { std::filesystem::create_directories(path); }
  ~ScratchDirectory() { std::filesystem::remove_all(path); }
  ScratchDirectory(const ScratchDirectory&) = delete;
  ScratchDirectory& operator=(const ScratchDirectory&) = delete;
};

}  // namespace cohaptic::testing
