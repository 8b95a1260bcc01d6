// trajectory_reach_warning: whether a tool's planned path ever comes near the scene. A
// trajectory written in one unit and read in another (metres as millimetres, say) moves
// the tool where nothing is to touch; the client warns at start instead of a silent session.
#pragma once

#include <Eigen/Geometry>

#include <string>

#include "common/haptics/trajectory.h"

namespace cohaptic {

/// Empty if `path` comes within one scene diagonal of `scene` (the bounding box of the
/// surfaces the server welcomed us with [m]) at some time; otherwise a warning saying how
/// far it stays and where the scene is. An empty box (no surface) warns of nothing.
std::string trajectory_reach_warning(const Trajectory& path, const Eigen::AlignedBox3d& scene);

}  // namespace cohaptic
