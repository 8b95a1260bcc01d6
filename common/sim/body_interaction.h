// BodyInteraction: one `interactions:` entry of a scene running in SceneSimulation: a
// mass-spring front body pressing on a condensed linear elastic body behind it (the
// several-objects paper, Sec. 2). Each step the front network's surface nodes, at their
// current positions, are tested against the behind body's surface at rest (linear body)
// through the pairs of nearest nodes, kept as interaction_step.h keeps them. The front
// body feels B through a backing (node_backing.h) over every front node
// that is behind B's surface or within kBackingReach of it: B's normal compliance at those
// nodes' target points (compliance_backing.h), a unilateral contact coupled across the
// nodes, which the front body's integrator solves every substep until the next step
// rebuilds it.
// Units: m, N. A step allocates (server side, not the haptic path).
#pragma once

#include <Eigen/Core>

#include "common/fem/compliance.h"
#include "common/interaction/interaction_step.h"
#include "common/interaction/node_pairs.h"
#include "common/interaction/surface_adjacency.h"
#include "common/mass_spring/node_backing.h"
#include "common/model/elastic_body.h"
#include "common/model/mass_spring_body.h"

namespace cohaptic {

/// How far in front of B's surface a front node joins the backing [m]: a node must be in it
/// before it reaches B, and between two steps (1 ms) a node moves far less than this (1 m/s
/// would take 1 mm).
inline constexpr double kBackingReach = 2e-3;
/// The backing's dashpots: critically damped contact of each node's mass on its own contact.
inline constexpr double kBackingDampingRatio = 1.0;

struct BodyInteraction {
  int front = -1;   ///< body index of the mass-spring front body
  int behind = -1;  ///< body index of the linear elastic behind body
  SurfaceAdjacency front_surface;
  SurfaceAdjacency behind_surface;
  NodePairList pairs;
};

/// Pairs every surface node of the front network at rest with the nearest surface node
/// of the behind body.
BodyInteraction make_body_interaction(int front, const MassSpringModel& front_body, int behind,
                                      const ElasticBody& behind_body);

/// One step at the front body's current positions; `columns` are the behind body's (row
/// nodes: at least its surface). Returns the backing the front body feels until the next.
NodeBacking step_body_interaction(BodyInteraction& interaction,
                                  const Eigen::Matrix3Xd& front_positions,
                                  const MassSpringModel& front_body, const ElasticBody& behind_body,
                                  ComplianceColumns& columns);

}  // namespace cohaptic
