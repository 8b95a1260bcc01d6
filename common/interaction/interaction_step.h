// One step of the interaction between an active (front) body and a condensed linear FEM
// body behind it (the several-objects paper, Sec. 2.1-2.5): update of pairs, collision
// tests, forcible displacement, the behind body's deformation, conveyance of its reaction
// to the active nodes, addition of pairs.
//
// Conveyance: the displaced nodes move by u = map * gaps (forcible_displacement.h), so by
// virtual work the reaction on the active nodes is -map^T f_c (f_c the forces holding the
// displaced nodes, condensed_response.h): for one polygon, each node's force weighted by
// w_k / sum w^2 and summed onto the active node. The active body uses it in its next
// deformation. A contact cannot pull: a collision whose reaction would pull its active
// node into the behind body (against the polygon's outward normal; e.g. a node that
// barely penetrates beside a deep one, where the behind body sinks further by itself) is
// released and the rest solved again, until none pulls (as rigid obstacles release held
// nodes). The paper keeps every collision; releasing is ours.
// Two workflows (Sec. 2.2, Fig. 2): the naive one deforms the behind body once per
// colliding pair (each pair's procedure carried out in full and its own reaction conveyed),
// the improved one once per step for all pairs. Both see the same displaced set, so their
// results are equal; the naive one costs a deformation per pair.
// Positions: the active body's current ones and the passive body's rest ones (linear).
// Units: m, N. The step allocates (small per-step lists); the haptic path uses a backing
// (linear_backing.h, node_backing.h) instead.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/fem/compliance.h"
#include "common/fem/dof_map.h"
#include "common/interaction/condensed_response.h"
#include "common/interaction/forcible_displacement.h"
#include "common/interaction/node_pairs.h"

namespace cohaptic {

enum class InteractionWorkflow { naive, improved };

/// The two bodies as a step sees them; the passive one condensed through its compliance
/// columns (row nodes: at least every node of its surface that can be displaced).
struct InteractingBodies {
  NodePositions active_positions;
  const SurfaceAdjacency& active_surface;
  NodePositions passive_positions;
  const SurfaceAdjacency& passive_surface;
  const DofMap& passive_dofs;
  ComplianceColumns& passive_columns;
};

struct InteractionStep {
  int pairs_updated = 0;
  int pairs_added = 0;
  int released = 0;  ///< collisions released because their reaction pulled
  std::vector<PolygonCollision> collisions;
  ForcibleDisplacement displacement;
  Eigen::VectorXd passive_forces;       ///< f_c, 3 per displaced node [N]
  Eigen::VectorXd passive_deformation;  ///< u of every row node of the passive columns [m]
  Eigen::VectorXd active_forces;  ///< reaction on each colliding active node, 3 per collision [N]
};

/// The collisions of the listed pairs (update of pairs is the caller's; see interaction_step).
std::vector<PolygonCollision> find_polygon_collisions(const NodePairList& list,
                                                      const InteractingBodies& bodies);

/// The pairs whose active node is behind a polygon around its passive node or at most
/// `reach` [m] in front of it (the detailed test's target, without the instant test): the
/// nodes a backing must hold before the next step, collided or about to.
std::vector<PolygonCollision> find_polygons_within(const NodePairList& list,
                                                   const InteractingBodies& bodies, double reach);

/// The pairs as a server step keeps them (Sec. 2.5): each walked to the nearest passive node,
/// then grown from the neighbours of every colliding node; then find_polygons_within(reach).
std::vector<PolygonCollision> keep_pairs_and_find_within(NodePairList& list,
                                                         const InteractingBodies& bodies,
                                                         double reach);

/// Reaction on the active nodes: -map^T passive_forces, 3 per collision [N].
Eigen::VectorXd convey_reaction(const ForcibleDisplacement& displacement,
                                const Eigen::VectorXd& passive_forces);

/// One step; `list` is updated and grown.
InteractionStep interaction_step(NodePairList& list, const InteractingBodies& bodies,
                                 InteractionWorkflow workflow,
                                 CondensedResponseWorkspace& workspace);

}  // namespace cohaptic
