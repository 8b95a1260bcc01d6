// MassSpringObjectSpec: a scene object of `model: mass_spring` (the thin-objects paper's
// body), as parsed by common/scene/parse_mass_spring.cpp: the tube's geometry and
// material, the supporting plane with its friction, the tool's friction, heated regions,
// the integrator's step, and what a client is sent (sections each side of the contact, IR
// rate). Units: SI (lengths already scaled by the scene's units).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "common/mass_spring/mass_spring_network.h"
#include "common/mass_spring/thermal_stiffness.h"
#include "common/mass_spring/tube_network.h"

namespace cohaptic {

/// What the server sends a client about a mass–spring body (the IR's sub-network).
struct MassSpringIrSettings {
  int sections = 4;          ///< free cross-sections each side of the contact's; one more each side is held (the rim)
  double rate_hz = 100;      ///< IRs per second while a tool is near
  double near_distance = 0.01;  ///< a tool this close to the surface gets IRs [m]
};

struct MassSpringObjectSpec {
  TubeGeometry tube;
  TubeMaterial material;
  double node_damping = 0.007;  ///< beta [N s/m]
  Eigen::Vector3d gravity = Eigen::Vector3d(0, 0, -9.81);
  std::optional<SupportPlane> plane;
  double tool_friction = 0.3;
  std::optional<double> time_step;  ///< [s]; default: kDefaultStepFraction of the critical step
  std::vector<HeatedRegion> heated;
  MassSpringIrSettings ir;
};

}  // namespace cohaptic
