// NodeBacking: a body behind a mass-spring network pressing back on some of its nodes,
// linear in their positions while the contacts hold:
//   f = -K (x - x*) + f0   over the backed nodes (3 rows and columns per node),
// with K symmetric positive semidefinite, x* the positions at which the backed nodes just
// touch the undisplaced behind body, f0 a constant force (the part of the backing that
// nodes outside a sub-network exert through K, zero on the whole network). A contact cannot
// pull: a node whose force points into the behind body (against its outward normal n) gets
// none, so a node that bounces off between two rebuilds is not held to the surface. The server's
// network and the sub-network an IR carries to a client integrate it every substep through
// the same function (integrate_network.h), so the client feels the behind body through
// the front one. Plain data; its evaluation is allocation-free and noexcept. Units: m, N, N/m.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

namespace cohaptic {

struct NodeBacking {
  std::vector<int> nodes;   ///< the network's backed nodes
  Eigen::MatrixXd stiffness;  ///< K, 3|nodes| square [N/m]
  Eigen::VectorXd targets;    ///< x*, 3 per node [m]
  Eigen::VectorXd offset;     ///< f0, 3 per node [N]
  Eigen::VectorXd normals;    ///< n, the behind body's outward unit normal, 3 per node

  bool empty() const { return nodes.empty(); }
};

/// forces.col(n) += f_n for each backed node n at `positions` (one column per network node)
/// whose f_n . n_n >= 0.
void add_node_backing_forces(const NodeBacking& backing, const Eigen::Ref<const Eigen::Matrix3Xd>& positions,
                             Eigen::Ref<Eigen::Matrix3Xd> forces) noexcept;

/// The backing of a sub-network: the backed nodes among `body_nodes` (the body's node of
/// each local node) in local indices; the others, at `body_positions` (the whole body's
/// current positions), fold into the offset.
NodeBacking sub_network_backing(const NodeBacking& whole, std::span<const std::int32_t> body_nodes,
                                const Eigen::Ref<const Eigen::Matrix3Xd>& body_positions);

/// Throws Error naming `what` when sizes, node indices (below node_count) or values are bad.
void check_node_backing(const NodeBacking& backing, int node_count, const char* what);

}  // namespace cohaptic
