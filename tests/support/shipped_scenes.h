// The shipped scenes a test runs as users would: those with both surgeons' scripts.
#pragma once

#include <string>
#include <vector>

namespace cohaptic::testing {

/// The scenes with both surgeons' scripts (scenes/<scene>/surgeon_a.yaml and surgeon_b.yaml
/// beside scenes/<scene>.yaml), as paths under scenes/ without ".yaml", sorted.
std::vector<std::string> scenes_with_surgeons();

/// A scene's path as a test's name: each character but a letter or digit becomes '_'.
std::string scene_test_name(const std::string& scene);

}  // namespace cohaptic::testing
