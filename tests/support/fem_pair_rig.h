// The paired boxes (paired_boxes.h) as an FEM pair (common/sim/fem_pair_coupling.h), for
// its tests and benchmarks: A pushed by a tool holding the node of its front face nearest
// the face's centre, moved `depth` along +x towards B; A's back-face nodes, at A's state
// without B, against B's rest surface; and the coupled contact solved. Units: m, N.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "common/fem/assemble_stiffness.h"
#include "common/fem/compliance.h"
#include "common/interaction/forcible_displacement.h"
#include "common/sim/fem_pair_coupling.h"
#include "common/sim/fem_pair_interaction.h"
#include "support/paired_boxes.h"

namespace cohaptic::testing {

std::vector<int> node_dofs(int node);

/// A pushed in B's absence.
struct FreePush {
  std::vector<int> tool_dofs;
  Eigen::VectorXd tool_values;   ///< the tool's displacement of its node [m]
  Eigen::VectorXd displacement;  ///< A's, 3N [m]
  Eigen::Vector3d tool_force;    ///< on A by the tool [N]
};

/// The push to `depth` [m]; `also_held` global dofs of A held at zero (A's back face, for
/// the fixed condition).
FreePush push_without_behind(const ElasticBody& front, double depth,
                             const std::vector<int>& also_held = {});

/// A's back-face nodes at `displacement` against B's rest surface, within kFemPairReach (the
/// scenes' candidates), each against the polygons around B's nearest surface node.
std::vector<PolygonCollision> back_face_candidates(const PairedBoxesRig& rig,
                                                   const Eigen::VectorXd& displacement);

/// The push, its candidates and the coupled contact (A's columns over its surface).
struct CoupledPush {
  PairedBoxesRig rig;
  FreePush free;
  std::vector<PolygonCollision> collisions;
  std::unique_ptr<ComplianceColumns> front_columns;
  FemPairContact contact;
  CoupledPush(double gap_mm, double depth);
  Eigen::Vector3d tool_force() const { return free.tool_force + contact.held_force_change; }
};

/// The pushing set S of a coupled push: A's nodes, B's normals there (columns) and B's
/// normal compliance A_B,SS between them.
struct PushingSupport {
  std::vector<int> nodes;
  Eigen::Matrix3Xd normals;
  Eigen::MatrixXd compliance;
};
PushingSupport pushing_support(const CoupledPush& push);

/// The tool's node and its neighbours on A's front face (within 30 mm): the nodes of M~.
std::vector<int> tool_neighbourhood(const CoupledPush& push);

/// K_ff of `a` plus the springs N support^-1 N^T on `nodes` (one normal each, `normals`'
/// columns): A resting on the support, the naive way.
SparseMatrix stiffness_with_support(const ElasticBody& a, const std::vector<int>& nodes,
                                    const Eigen::Matrix3Xd& normals,
                                    const Eigen::MatrixXd& support);

}  // namespace cohaptic::testing
