#include "common/sim/body_interaction.h"

#include "common/interaction/compliance_backing.h"

namespace cohaptic {

BodyInteraction make_body_interaction(int front, const MassSpringModel& front_body, int behind,
                                      const ElasticBody& behind_body) {
  BodyInteraction interaction;
  interaction.front = front;
  interaction.behind = behind;
  const MassSpringNetwork& network = front_body.network;
  interaction.front_surface = make_surface_adjacency(
      std::vector<Triangle>(network.triangles.begin(), network.triangles.end()),
      network.node_count());
  interaction.behind_surface =
      make_surface_adjacency(behind_body.surface.triangles, behind_body.mesh.node_count());
  interaction.pairs = make_node_pairs(network.surface_nodes, network.rest_positions,
                                      behind_body.surface.nodes, behind_body.mesh.nodes);
  return interaction;
}

NodeBacking step_body_interaction(BodyInteraction& interaction,
                                  const Eigen::Matrix3Xd& front_positions,
                                  const MassSpringModel& front_body, const ElasticBody& behind_body,
                                  ComplianceColumns& columns) {
  const InteractingBodies bodies{front_positions,        interaction.front_surface,
                                 behind_body.mesh.nodes, interaction.behind_surface,
                                 behind_body.dofs,       columns};
  // B's own response to the collisions is not solved here: the front body feels B through
  // the backing alone. The backing holds every node that collided or may collide before the
  // next step; its contact set is solved at every substep (node_backing.h).
  const std::vector<PolygonCollision> within =
      keep_pairs_and_find_within(interaction.pairs, bodies, kBackingReach);
  if (within.empty()) return {};
  const MassSpringNetwork& network = front_body.network;
  return compliance_backing(within, columns, network.mass, network.parameters.time_step,
                            kBackingDampingRatio);
}

}  // namespace cohaptic
