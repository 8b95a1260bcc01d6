// A recorded hand motion as a trajectory, so that a live session can be driven by it
// (`--device replay:FILE[:user]`): the own tool positions of a client's recording, or one
// user's tool positions from a server's recording (the user given by its slot number).
// Times start at 0 with the first recorded position; units m, s.
#pragma once

#include <filesystem>
#include <string>

#include "common/haptics/trajectory.h"

namespace cohaptic {

/// Throws Error naming the file if it holds no positions (for that user).
Trajectory recorded_motion(const std::filesystem::path& file, const std::string& user);

}  // namespace cohaptic
