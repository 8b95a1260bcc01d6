// MassSpringModel: a mass–spring body compiled from its scene object (`model: mass_spring`),
// never changed afterwards: the tube's or the lattice's network (its fixed nodes held) with
// its heated springs and parameters, the cross-section of every node (for the IR's
// sub-network; a lattice's layers across its longest axis), and the critical time step. One
// of the body kinds a Model holds (common/model/model.h). Units: SI.
#pragma once

#include <string>
#include <vector>

#include "common/mass_spring/mass_spring_network.h"
#include "common/mass_spring/mass_spring_spec.h"

namespace cohaptic {

struct MassSpringModel {
  std::string name;  ///< the scene object's name
  MassSpringObjectSpec spec;
  MassSpringNetwork network;  ///< rest_positions is the initial state
  std::vector<int> section_of_node;
  int section_count = 0;
  double critical_time_step = 0;  ///< 2/omega_max at rest [s]
  int heated_springs = 0;
};

/// Builds the body; throws SceneError naming `where` for a spec the generator rejects, a
/// heating factor out of range, or a time step above the critical one.
MassSpringModel build_mass_spring_body(const std::string& name, const MassSpringObjectSpec& spec,
                                       const std::string& where);

}  // namespace cohaptic
