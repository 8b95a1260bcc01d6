// NodeBacking: a body behind a mass-spring network pressing back on some of its nodes, as
// one contact spring-damper per node along the behind body's outward normal n:
//   g = (x - x*) . n   (x* the point of the behind body's rest surface under the node),
//   f = max(0, -k g - c (v . n)) n   while g < 0, and nothing while g >= 0.
// Each node's force is the gradient of its own convex potential k min(0, g)^2 / 2 plus a
// dashpot that only acts in contact, so the backing can only take energy out of the
// network, and each node engages and releases on its own gap at every substep: it cannot
// fall into the behind body unresisted for the rest of a step, nor be pushed out by a force
// stored from an earlier position. A contact cannot pull: the dashpot never holds a node
// that leaves. The server's network and the sub-network an IR carries to a client integrate
// it every substep through the same function (integrate_network.h), so the client feels the
// behind body through the front one. Plain data; its evaluation is allocation-free and
// noexcept. Units: m, N, N/m, N s/m.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

namespace cohaptic {

struct NodeBacking {
  std::vector<int> nodes;     ///< the network's backed nodes
  Eigen::VectorXd stiffness;  ///< k per node, along its normal [N/m] >= 0
  Eigen::VectorXd damping;    ///< c per node, along its normal [N s/m] >= 0
  Eigen::VectorXd targets;    ///< x*, 3 per node [m]
  Eigen::VectorXd normals;    ///< n, the behind body's outward unit normal, 3 per node

  bool empty() const { return nodes.empty(); }
};

/// forces.col(n) += f_n for each backed node n at `positions` and `velocities` (one column
/// per network node).
void add_node_backing_forces(const NodeBacking& backing, const Eigen::Ref<const Eigen::Matrix3Xd>& positions,
                             const Eigen::Ref<const Eigen::Matrix3Xd>& velocities,
                             Eigen::Ref<Eigen::Matrix3Xd> forces) noexcept;

/// The backing of a sub-network: the backed nodes among `body_nodes` (the body's node of
/// each local node), in local indices.
NodeBacking sub_network_backing(const NodeBacking& whole, std::span<const std::int32_t> body_nodes);

/// Throws Error naming `what` when sizes, node indices (below node_count) or values are bad
/// (negative or non-finite stiffness or damping, normals not of unit length).
void check_node_backing(const NodeBacking& backing, int node_count, const char* what);

}  // namespace cohaptic
