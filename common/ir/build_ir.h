// Building one user's intermediate representation from the simulation state.
//
// The patch is centred on the touchable triangle nearest the user's tool (in contact or
// not, so the client can detect contact itself); the other users' nearest triangles are
// included as remote contacts; M~ comes from the incremental condensation for
// C = patch nodes + remote contact nodes and the current boundary set B. Under the sphere
// contact model the patch also holds every touchable triangle with a node inside the
// sphere (sphere_patch), every remote sphere's patch nodes are contact nodes too, so are
// the nodes the server's state solve holds against a rigid obstacle (its obstacle rows), and
// the IR carries their normal compliance, cut from the server's (normal_compliance.h),
// instead of M~.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "common/condense/incremental_condensation.h"
#include "common/condense/normal_compliance.h"
#include "common/ir/intermediate_representation.h"
#include "common/model/elastic_body.h"

namespace cohaptic {

/// One user's tool as the server knows it.
struct UserTool {
  int user = 0;                                          ///< slot
  Eigen::Vector3d position = Eigen::Vector3d::Zero();    ///< [m]
  double radius = 0;                                     ///< [m]
  int nearest_triangle = -1;  ///< touchable surface triangle nearest the tool (see nearest_touchable_triangle)
  /// Sphere model: nodes outside the sphere at rest that the simulation's state has it push;
  /// their triangles join its patch (sphere_patch).
  std::vector<int> carried_nodes;
};

struct IrBuildOptions {
  int patch_rings = 1;  ///< 0: the nearest triangle only; each ring adds the triangles around it
  IrPrecision precision = IrPrecision::f64;
  ContactModel contact_model = ContactModel::node_translation;
  double force_limit = 3.3;  ///< [N]
  /// B truncation: a held node is left out of the IR (its columns of M_CB and its u_B; it is
  /// listed in truncated_node_ids) when the norm of its columns is below this fraction of
  /// the largest node's. 0 keeps all;
  /// M_CC is unchanged either way (the node stays held, only its displacement's effect on
  /// the contact forces is dropped).
  double boundary_truncation = 0;
};

/// Which nodes of `boundary` B truncation keeps: those whose columns of `m_cb` (free dofs
/// of B, node by node) have a norm of at least `threshold` times the largest node's.
std::vector<bool> kept_boundary_nodes(const DofMap& dofs, std::span<const int> boundary, const Eigen::MatrixXd& m_cb,
                                      double threshold);

/// The touchable triangle nearest `position` (ties to the one it is deepest below).
int nearest_touchable_triangle(const ElasticBody& body, const Eigen::Vector3d& position);

/// Loads a body carries besides its tools and held nodes, as build_ir reads them: the
/// displacement u0 they cause at the given free dofs with nothing held [m] (an FEM pair's
/// support closing the gaps its nodes had at rest, supported_compliance.h).
using RestDisplacement = std::function<Eigen::VectorXd(std::span<const int> dofs)>;

/// Under the sphere contact model: the server's normal compliance, over every node the IR
/// can hold (its row nodes), the slots of it that the server's state pushes, its candidates
/// an obstacle holds (ascending), and per volume node the obstacle constraints
/// (obstacle_constraints.h) that give their gaps.
struct SphereIrSource {
  const NormalCompliance* normal = nullptr;
  std::span<const int> contact_slots;
  std::span<const int> obstacle_nodes;
  std::span<const SphereConstraint> obstacles;
};

/// IR for users[user_index]. `boundary_displacement` gives u for each node of
/// condensation.boundary_nodes(), in that order. With `rest`, the IR carries the rest forces
/// f_rest = -M~ u0 over its nodes (every held node's, truncated or not). Under the sphere
/// contact model `sphere` must be given (and `rest` not). Throws Error if the user's nearest
/// triangle is unknown or holds a boundary node, or a row node the sphere model can hold has
/// no slot in sphere.normal.
IntermediateRepresentation build_ir(const ElasticBody& body, IncrementalCondensation& condensation,
                                    std::span<const UserTool> users, std::size_t user_index,
                                    std::span<const Eigen::Vector3d> boundary_displacement,
                                    const IrBuildOptions& options, std::uint64_t epoch, double simulation_time,
                                    const RestDisplacement& rest = {}, const SphereIrSource& sphere = {});

}  // namespace cohaptic
