// The several-objects paper's pushing test (Sec. 3.2), solved quasi-statically: the front
// object A, a mass-spring network fixed on its bottom, is pushed at one node of its front
// face along a coordinate axis to each depth, with its back face (towards B) in one of
// three conditions: free, fixed, or resting on B, a condensed linear FEM body.
//
// Quasi-static: the paper pushes at 5 mm/s, slowly against A's lowest mode, so its dampers
// and masses carry no force and the force at each depth is the static one. A's springs are
// linearised about rest (network_stiffness.h) and B is linear, so within one set of
// pressing nodes the force is linear in depth. On B: A's back nodes are paired with B's
// surface and collide with its polygons at rest (A touches B); B's condensed stiffness
// mapped onto them (the linear backing, f = -K (u - u*)) is added to A's; a back node that
// B would pull is released and the push solved again, until none pulls (as
// interaction_step.h does). The tool holds the node it pushes (the paper prescribes the
// pushed node's displacement): the node moves along the push axis and not across it, as a
// tool that grips the surface drives it in time (tool_coupling.h with enough friction).
// Units: m, N.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "common/fem/compliance.h"
#include "common/fem/dof_map.h"
#include "common/interaction/forcible_displacement.h"
#include "common/interaction/linear_backing.h"
#include "common/interaction/surface_adjacency.h"
#include "common/mass_spring/mass_spring_network.h"
#include "common/model/elastic_body.h"

namespace cohaptic {

enum class BackCondition { free, fixed, on_behind };

const char* back_condition_name(BackCondition condition);

/// The front object A and how it is pushed.
struct PushedFront {
  Eigen::Matrix3Xd rest_positions;  ///< [m]
  std::vector<Spring> springs;
  std::vector<AxisMask> fixed_axes;  ///< per node: its support (the bottom)
  SurfaceAdjacency surface;
  std::vector<int> back_face;  ///< nodes on the face towards B (fixed in condition `fixed`)
  int tool_node = -1;
  int push_axis = 0;  ///< pushed along + this axis
};

/// The condensed FEM body B behind A (its columns' row nodes: at least its surface).
struct BehindBody {
  const ElasticBody& body;
  const SurfaceAdjacency& surface;
  ComplianceColumns& columns;
};

struct PushSample {
  double depth = 0;                          ///< [m]
  double force = 0;                          ///< the tool's force along the push axis [N]
  Eigen::VectorXd displacement;              ///< A's, 3 per node [m]
  std::vector<PolygonCollision> collisions;  ///< on B: the back nodes pressing B
  ForcibleDisplacement forcible;             ///< on B: B's displaced nodes per gap
  int released = 0;  ///< on B: back nodes released because B would pull them
};

/// The push to each of `depths` [m] in `condition`; `behind` is required for on_behind
/// (throws Error without it, or when no back node touches B).
std::vector<PushSample> push_front(const PushedFront& front, BackCondition condition,
                                   const BehindBody* behind, std::span<const double> depths);

}  // namespace cohaptic
