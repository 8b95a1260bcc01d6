// The brain scene (scenes/brain.yaml: tissue, support, skull, tools) with another of the
// meshes in scenes/brain/. The shipped scene's graded mesh takes seconds to factor and
// tens of seconds for its compliance, so the tests of the brain's mechanics, which need
// many solves, run on its 9 mm mesh (kCoarseBrainMesh); the shipped scene itself is served
// whole by the shipped-scenes session test.
#pragma once

#include <filesystem>
#include <string>

#include "common/scene/scene.h"

namespace cohaptic::testing {

/// The 9 mm brain mesh (scenes/brain/brain.msh).
inline constexpr const char* kCoarseBrainMesh = "brain.msh";

/// scenes/brain.yaml's text with `mesh` (a file name in scenes/brain/) in place of its own
/// and every file path absolute, so that the text may be saved anywhere.
std::string brain_scene_text(const std::string& mesh);

/// The brain scene with `mesh`, loaded.
Scene brain_scene(const std::string& mesh);

/// The brain scene with `mesh`, written to `directory`/brain.yaml; that file.
std::filesystem::path write_brain_scene(const std::filesystem::path& directory,
                                        const std::string& mesh);

}  // namespace cohaptic::testing
