// NodeBacking: a body B behind a mass-spring network pressing back on some of its nodes
// through B's dense normal compliance, so that pressing one node lowers B's surface under
// its neighbours (the several-objects paper's coupling, carried by the IR).
//
// Node i of the backing has the gap g_i = (x_i - x*_i) . n_i + o_i to B's rest surface (x*
// the point under it, n B's outward unit normal, o an offset: zero on the server, the
// displacement by pushes on nodes outside a client's sub-network). Its push lambda_i >= 0
// [N] along n_i solves the unilateral problem
//   w = A lambda + g >= 0,   lambda >= 0,   lambda_i w_i = 0,
// A [m/N] the backed nodes' normal compliance (B's compliance at the target points through
// the barycentric weights, plus each node's own contact compliance on the diagonal, which
// makes A positive definite; compliance_backing.h): B's surface gives way exactly as far
// as the nodes that touch it, and a node B would have to pull is released. The pushes are
// the gradient of the convex potential max_{lambda >= 0} (-lambda.g - lambda.A lambda / 2)
// = lambda.A lambda / 2 (B's elastic energy), so the backing stores and returns energy and
// never creates it; a dashpot c_i acts along n_i on the nodes in contact only, and the
// total push of a node is clipped at zero (a contact cannot pull), which only dissipates.
// The contact set is exact at every substep (the block principal pivoting solve of
// unilateral_contact_solve.h, warm-started from the last substep's set).
// NodeBacking is plain data; NodeBackingSolve is the evaluation's workspace (in
// MassSpringState), sized off the haptic path by prepare_backing_solve; evaluation is then
// allocation-free and noexcept. Units: m, N, m/N, N s/m.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

namespace cohaptic {

struct NodeBacking {
  std::vector<int> nodes;      ///< the network's backed nodes
  Eigen::MatrixXd compliance;  ///< A, |nodes| square, symmetric positive definite [m/N]
  Eigen::VectorXd offsets;     ///< o per node [m]
  Eigen::VectorXd damping;     ///< c per node, along its normal [N s/m] >= 0
  Eigen::VectorXd targets;     ///< x*, 3 per node [m]
  Eigen::VectorXd normals;     ///< n, the behind body's outward unit normal, 3 per node

  bool empty() const { return nodes.empty(); }
};

/// The backing's evaluation workspace and its last answer.
struct NodeBackingSolve {
  std::vector<std::uint8_t> active;  ///< 1: in contact (the warm start of the next solve)
  Eigen::VectorXd pushes;            ///< lambda per backed node, of the latest evaluation [N]
  Eigen::VectorXd gaps;              ///< scratch: g
  Eigen::VectorXd solved;            ///< scratch: the solve's lambda
  Eigen::MatrixXd factor;            ///< scratch: Cholesky factor of A_SS
  std::vector<int> order;            ///< scratch
  std::uint64_t evaluations = 0;
  /// Evaluations whose solve failed within its work budget, or whose workspace was not
  /// prepared for the backing (see add_node_backing_forces for what they did instead).
  std::uint64_t failures = 0;
};

/// Sizes `solve` for `backing` with no node in contact and no pushes (allocates).
void prepare_backing_solve(NodeBackingSolve& solve, const NodeBacking& backing);

/// forces.col(n) += f_n for each backed node n at `positions` and `velocities` (one column
/// per network node), solving for the pushes in `solve` (prepared for `backing`). When the
/// solve fails, each node keeps its previous push while its gap is negative (none otherwise)
/// and the failure is counted.
void add_node_backing_forces(const NodeBacking& backing, NodeBackingSolve& solve,
                             const Eigen::Ref<const Eigen::Matrix3Xd>& positions,
                             const Eigen::Ref<const Eigen::Matrix3Xd>& velocities,
                             Eigen::Ref<Eigen::Matrix3Xd> forces) noexcept;

/// B's elastic energy under `pushes` [J]: lambda.A lambda / 2, the backing's potential.
double backing_energy(const NodeBacking& backing,
                      const Eigen::Ref<const Eigen::VectorXd>& pushes) noexcept;

/// The backing of a sub-network: the backed nodes among `body_nodes` (the body's node of
/// each local node), in local indices; the `pushes` of the others (the whole backing's,
/// per its node) are held and displace B's surface under the kept ones (their offsets).
NodeBacking sub_network_backing(const NodeBacking& whole,
                                const Eigen::Ref<const Eigen::VectorXd>& pushes,
                                std::span<const std::int32_t> body_nodes);

/// Throws Error naming `what` when sizes, node indices (below node_count) or values are bad
/// (a compliance not symmetric positive definite, offsets or damping not finite, negative
/// damping, normals not of unit length).
void check_node_backing(const NodeBacking& backing, int node_count, const char* what);

}  // namespace cohaptic
