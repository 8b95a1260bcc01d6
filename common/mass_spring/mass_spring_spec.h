// MassSpringObjectSpec: a scene object of `model: mass_spring`, as parsed by
// common/scene/parse_mass_spring.cpp: either the thin-objects paper's tube (its geometry and
// material) or the several-objects paper's box lattice (spring_lattice.h); and for both
// the nodes held still, the supporting plane with its friction, the tool's friction, heated
// regions, the integrator's step, and what a client is sent (sections each side of the contact, IR
// rate). Units: SI (lengths already scaled by the scene's units).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "common/mass_spring/mass_spring_network.h"
#include "common/mass_spring/spring_lattice.h"
#include "common/mass_spring/thermal_stiffness.h"
#include "common/mass_spring/tube_network.h"
#include "common/mesh/node_selector.h"

namespace cohaptic {

/// What the server sends a client about a mass–spring body (the IR's sub-network).
struct MassSpringIrSettings {
  int sections =
      4;  ///< free cross-sections each side of the contact's; one more each side is held (the rim)
  double rate_hz = 100;         ///< IRs per second while a tool is near
  double near_distance = 0.01;  ///< a tool this close to the surface gets IRs [m]
};

struct MassSpringObjectSpec {
  TubeGeometry tube;                         ///< the tube's, unless `lattice` is set
  TubeMaterial material;                     ///< the tube's, unless `lattice` is set
  std::optional<SpringLatticeSpec> lattice;  ///< set: the body is this lattice, not a tube
  std::vector<NodeSelector>
      fixed;  ///< nodes held still (a lattice's support, a vessel's anchored ends)
  double node_damping = 0.007;  ///< beta [N s/m]
  Eigen::Vector3d gravity = Eigen::Vector3d(0, 0, -9.81);
  std::optional<SupportPlane> plane;
  double tool_friction = 0.3;
  std::optional<double> time_step;  ///< [s]; default: kDefaultStepFraction of the critical step
  std::vector<HeatedRegion> heated;
  MassSpringIrSettings ir;
};

}  // namespace cohaptic
