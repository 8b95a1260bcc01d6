// Obstacle: a rigid body a deformable object may not pass (an infinite plane or a triangle
// surface such as the inner skull), as compiled from a scene. ObstacleDistance measures
// against it. Units: m.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>

#include "common/mesh/triangle_surface.h"

namespace cohaptic {

struct Obstacle {
  std::string name;
  TriangleSurface surface;                                           ///< [m]; empty for a plane
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> plane;  ///< point [m], unit normal
};

}  // namespace cohaptic
