// FemPairInteraction: one `interactions:` entry of a scene whose front and behind objects
// are both linear elastic (FEM against FEM), run in the server's step.
//
// Each step, once the front body A's tools and held nodes are known: A's surface at its
// state without B (what A does alone) against B's surface at rest, through the pairs of
// nearest nodes kept as body_interaction.h keeps them; the nodes behind B's surface or at
// most kFemPairReach in front of it are the candidates. Their pushes come from the coupled
// unilateral problem (fem_pair_coupling.h), A's tools' nodes and held nodes staying where
// they are (the translation contact model holds a tool's triangle: other models are
// refused). The pushes are then loads on both bodies: +n lambda on A's node, -w n lambda on
// B's polygon (state_solve.h's applied loads), so both show their deformation; and B is
// folded into the compliance A's IRs condense over as a support on the pushing set S
// (supported_compliance.h), rebuilt when S changes, so a user feels B through A.
// Exact for both bodies' linear elasticity about rest with B's polygons fixed over a step,
// frictionless. The IR's support is B's compliance at the targets S had when it formed and
// bilateral (a node that would release is not seen until S changes); a node that closed a
// gap before it pushed is held on B's plane by it, which the IR carries as rest forces.
// Units: m, N. A step allocates (server side, not the haptic path).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "common/fem/compliance.h"
#include "common/interaction/node_pairs.h"
#include "common/interaction/surface_adjacency.h"
#include "common/model/elastic_body.h"
#include "common/sim/fem_pair_coupling.h"
#include "common/sim/simulation.h"

namespace cohaptic {

/// How far in front of B's surface a node of A is a candidate [m]: a push elsewhere may
/// draw a node that is clear of B towards it, and a step moves a node far less than this.
inline constexpr double kFemPairReach = 2e-3;

struct FemPairInteraction {
  int front = -1;   ///< body index of A
  int behind = -1;  ///< body index of B
  SurfaceAdjacency front_surface;
  SurfaceAdjacency behind_surface;
  NodePairList pairs;
  std::vector<PolygonCollision> collisions;  ///< the latest step's candidates
  FemPairContact contact;                    ///< the latest step's coupled solve
  long failures = 0;  ///< steps whose coupled problem was not positive definite
};

/// The pushes of a step as loads on each body, and B as A's support on the pushing set.
struct FemPairLoads {
  AppliedLoads front;
  AppliedLoads behind;
  std::vector<int> support_nodes;      ///< S: A's nodes that push, in candidate order
  Eigen::Matrix3Xd support_normals;    ///< B's outward normal at each
  Eigen::MatrixXd support_compliance;  ///< A_B,SS [m/N]
  Eigen::VectorXd support_gaps;  ///< g0 per node of S: its gap to its polygon's plane at rest [m]
};

/// Pairs every surface node of A at rest with the nearest surface node of B.
FemPairInteraction make_fem_pair_interaction(int front, const ElasticBody& front_body, int behind,
                                             const ElasticBody& behind_body);

/// One step from `front_alone`, A's state solved without B (its contact and boundary dofs
/// are the ones held). Both column sets' rows must hold the bodies' surfaces.
FemPairLoads step_fem_pair(FemPairInteraction& interaction, const ElasticBody& front_body,
                           ComplianceColumns& front_columns, const StateSolution& front_alone,
                           const ElasticBody& behind_body, ComplianceColumns& behind_columns);

/// The step as A's Simulation's coupling: the loads set on both simulations, and A's
/// support replaced when S changed.
void couple_fem_pair(FemPairInteraction& interaction, Simulation& front,
                     const ElasticBody& front_body, ComplianceColumns& front_columns,
                     Simulation& behind, const ElasticBody& behind_body,
                     ComplianceColumns& behind_columns);

}  // namespace cohaptic
