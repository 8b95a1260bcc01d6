// MassSpringNetwork: the immutable description of a mass–spring body (the thin-objects
// paper, Sec. 4): point masses joined by spring–dampers, the surface triangles a tool
// collides with, and the physical parameters (gravity, nodal damping, a supporting plane
// with static and dynamic friction, the tool's friction). The whole body on the server and
// the sub-network an IR carries to a client are both networks of this kind, integrated by
// the same functions (integrate_network.h).
//
// Held nodes do not integrate their forces: they move at their own velocity (zero for a
// pinned node; the server's velocity for the rim of a sub-network). Units: m, kg, N/m,
// N s/m, s. Node indices are 0-based; triangles are counter-clockwise seen from outside.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace cohaptic {

struct Spring {
  int a = 0, b = 0;        ///< node indices, a != b
  double rest_length = 0;  ///< l0 [m] > 0
  double stiffness = 0;    ///< k [N/m] >= 0 (Eq. 1, scaled by heating, Eq. 7)
  double damping = 0;      ///< k^d [N s/m] >= 0 (Eq. 2: alpha k)
};

/// The plane the body lies on (its normal N_p points up, out of the floor) and the
/// Coulomb friction between them.
struct SupportPlane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    ///< [m]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit
  double static_friction = 0;                         ///< mu_s >= mu_d
  double dynamic_friction = 0;                        ///< mu_d >= 0
};

struct MassSpringParameters {
  Eigen::Vector3d gravity = Eigen::Vector3d(0, 0, -9.81);  ///< [m/s^2]
  double node_damping = 0;                                 ///< beta [N s/m]: -beta v on every node
  double tool_friction = 0;  ///< mu between tool and surface: caps Eq. (5)'s tangential part
  double time_step = 0;  ///< the integrator's largest step [s] > 0; longer periods are substepped
  std::optional<SupportPlane> plane;
};

struct MassSpringNetwork {
  Eigen::Matrix3Xd rest_positions;  ///< [m] (also the initial state)
  Eigen::VectorXd mass;             ///< per node [kg] > 0
  std::vector<std::uint8_t> held;   ///< per node: 1 if held (moves at its own velocity)
  std::vector<Spring> springs;
  std::vector<std::array<int, 3>> triangles;  ///< the surface a tool collides with
  MassSpringParameters parameters;

  /// Triangles around each node, compressed: node n's are
  /// node_triangles[node_triangle_start[n] .. node_triangle_start[n + 1]).
  std::vector<int> node_triangle_start, node_triangles;
  std::vector<int> surface_nodes;  ///< nodes of at least one triangle, ascending

  int node_count() const { return static_cast<int>(mass.size()); }
};

/// Fills the adjacency (node_triangle_start, node_triangles, surface_nodes) from the
/// triangles. Call after changing the triangles.
void index_surface(MassSpringNetwork& network);

/// Checks sizes, indices, finiteness and signs; throws Error naming `what` and the first
/// offending node, spring or triangle.
void check_network(const MassSpringNetwork& network, const char* what);

}  // namespace cohaptic
