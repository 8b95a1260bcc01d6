#include "common/interaction/interaction_step.h"

#include <optional>

#include "common/interaction/node_polygon_collision.h"

namespace cohaptic {

namespace {

// The collisions of the listed pairs whose active node `target_of` finds a polygon for.
template <typename TargetOf>
std::vector<PolygonCollision> collect_polygon_collisions(const NodePairList& list,
                                                         const InteractingBodies& bodies,
                                                         TargetOf target_of) {
  std::vector<PolygonCollision> collisions;
  for (std::size_t index = 0; index < list.pairs.size(); ++index) {
    const NodePair& pair = list.pairs[index];
    const Eigen::Vector3d active = bodies.active_positions.col(pair.active);
    const std::optional<PolygonTarget> target = target_of(active, pair.passive);
    if (!target) continue;
    collisions.push_back(
        {static_cast<int>(index), pair.active,
         bodies.passive_surface.triangles[static_cast<std::size_t>(target->triangle)],
         target->weights, target->point, active - target->point, target->normal});
  }
  return collisions;
}

}  // namespace

std::vector<PolygonCollision> find_polygon_collisions(const NodePairList& list,
                                                      const InteractingBodies& bodies) {
  return collect_polygon_collisions(list, bodies, [&](const Eigen::Vector3d& active, int passive) {
    return node_polygon_collision(active, passive, bodies.passive_positions,
                                  bodies.passive_surface);
  });
}

std::vector<PolygonCollision> find_polygons_within(const NodePairList& list,
                                                   const InteractingBodies& bodies, double reach) {
  return collect_polygon_collisions(list, bodies, [&](const Eigen::Vector3d& active, int passive) {
    std::optional<PolygonTarget> target =
        detailed_collision_test(active, passive, bodies.passive_positions, bodies.passive_surface);
    if (target && (active - target->point).dot(target->normal) > reach) target.reset();
    return target;
  });
}

std::vector<PolygonCollision> keep_pairs_and_find_within(NodePairList& list,
                                                         const InteractingBodies& bodies,
                                                         double reach) {
  update_node_pairs(list, bodies.active_positions, bodies.passive_positions,
                    bodies.passive_surface);
  std::vector<int> colliding;
  for (const PolygonCollision& collision : find_polygon_collisions(list, bodies))
    colliding.push_back(collision.pair);
  add_neighbour_pairs(list, colliding, bodies.active_positions, bodies.active_surface,
                      bodies.passive_positions, bodies.passive_surface);
  return find_polygons_within(list, bodies, reach);
}

Eigen::VectorXd convey_reaction(const ForcibleDisplacement& displacement,
                                const Eigen::VectorXd& passive_forces) {
  return -displacement.map.transpose() * passive_forces;
}

namespace {

// The forcible displacement of step.collisions, the behind body's reaction and
// deformation, and the reaction conveyed to the active nodes.
void respond(InteractionStep& step, const InteractingBodies& bodies, InteractionWorkflow workflow,
             CondensedResponseWorkspace& workspace) {
  step.displacement = forcible_displacement(step.collisions, bodies.passive_dofs.fixed_axes);
  const auto displaced = 3 * static_cast<Eigen::Index>(step.displacement.nodes.size());
  const auto collided = 3 * static_cast<Eigen::Index>(step.collisions.size());
  step.passive_forces = Eigen::VectorXd::Zero(displaced);
  step.passive_deformation = Eigen::VectorXd::Zero(
      3 * static_cast<Eigen::Index>(bodies.passive_columns.row_nodes().size()));
  step.active_forces = Eigen::VectorXd::Zero(collided);
  const auto deform = [&] {
    condensed_reaction(bodies.passive_columns, bodies.passive_dofs, step.displacement.nodes,
                       step.displacement.displacement, step.passive_forces, workspace);
    condensed_deformation(bodies.passive_columns, step.displacement.nodes, step.passive_forces,
                          step.passive_deformation);
  };
  if (workflow == InteractionWorkflow::improved) {
    if (collided > 0) deform();
    step.active_forces = convey_reaction(step.displacement, step.passive_forces);
  } else {
    for (Eigen::Index k = 0; k < collided; k += 3) {
      deform();
      step.active_forces.segment<3>(k) =
          -step.displacement.map.middleCols<3>(k).transpose() * step.passive_forces;
    }
  }
}

// Drops the collisions whose conveyed reaction pulls the active node into the behind body;
// returns how many.
int release_pulling(InteractionStep& step) {
  std::vector<PolygonCollision> kept;
  for (std::size_t k = 0; k < step.collisions.size(); ++k)
    if (step.active_forces.segment<3>(3 * static_cast<Eigen::Index>(k))
            .dot(step.collisions[k].normal) >= 0)
      kept.push_back(step.collisions[k]);
  const auto released = static_cast<int>(step.collisions.size() - kept.size());
  step.collisions = std::move(kept);
  return released;
}

}  // namespace

InteractionStep interaction_step(NodePairList& list, const InteractingBodies& bodies,
                                 InteractionWorkflow workflow,
                                 CondensedResponseWorkspace& workspace) {
  InteractionStep step;
  step.pairs_updated = update_node_pairs(list, bodies.active_positions, bodies.passive_positions,
                                         bodies.passive_surface);
  step.collisions = find_polygon_collisions(list, bodies);
  // Every node that collided grows the pairs, released or not: it touches the surface.
  std::vector<int> colliding;
  colliding.reserve(step.collisions.size());
  for (const PolygonCollision& collision : step.collisions) colliding.push_back(collision.pair);
  // Each round releases at least one collision or stops.
  respond(step, bodies, workflow, workspace);
  while (const int released = release_pulling(step)) {
    step.released += released;
    respond(step, bodies, workflow, workspace);
  }
  step.pairs_added =
      add_neighbour_pairs(list, colliding, bodies.active_positions, bodies.active_surface,
                          bodies.passive_positions, bodies.passive_surface);
  return step;
}

}  // namespace cohaptic
