#include "common/mass_spring/mass_spring_state.h"

namespace cohaptic {

MassSpringState make_state(const MassSpringNetwork& network) {
  MassSpringState state;
  state.positions = network.rest_positions;
  state.velocities = Eigen::Matrix3Xd::Zero(3, network.node_count());
  state.forces = Eigen::Matrix3Xd::Zero(3, network.node_count());
  return state;
}

}  // namespace cohaptic
