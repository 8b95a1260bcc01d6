// IntermediateRepresentation (IR): what the simulation exports to one user's haptic loop.
// An envelope (who, when, the tool, the force limit) around one body, a variant over the
// body kinds: the client prepares and evaluates whichever kind the server sent. The
// mass-spring body's IR is in mass_spring_ir.h, the home-spring (laparoscopy) body's is
// the HomeSpringPatch itself (common/laparoscopy/home_spring_patch.h), the separating
// tissue's is in separation_ir.h.
//
// CondensedFemIr, the linear elastic body's (the paper's Sec. II-C): the local contact
// geometry and M~ = (M_CC M_CB). Nodes are numbered locally: first the user's own contact patch
// (the triangle nearest its tool and `patch_rings` rings of neighbours), then the other users'
// contact triangles (nodes not already in the patch), then the colliding boundary nodes B. The
// first `row_node_count` nodes (patch and remote contacts) are the contact nodes C: M~ has a row
// per free dof of C and a column per free dof of every node, node-major, axes x, y, z,
// fixed axes left out. With f = M~ (u_C, u_B) (+ f_rest, rest_forces, when the body carries
// other loads): the forces on C for prescribed displacements of C and B, every other node
// unloaded. u_B is where the boundary nodes are held.
//
// Units: m, N, N/m, s. A plain value type: the wire format (next layer) mirrors it field by
// field. With precision f32 the M~ and u_B values are rounded to float (as they travel);
// the server always inverts in double.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <variant>
#include <vector>

#include "common/fem/dof_map.h"
#include "common/ir/compliance_rows.h"
#include "common/ir/mass_spring_ir.h"
#include "common/ir/separation_ir.h"
#include "common/kinds/body_kinds.h"
#include "common/kinds/contact_model.h"
#include "common/laparoscopy/home_spring_patch.h"
#include "common/mesh/tet_mesh.h"

namespace cohaptic {

enum class IrPrecision { f64, f32 };

struct IrTriangle {
  std::array<int, 3> nodes{};  ///< local node indices, counter-clockwise seen from outside
  int surface_index = 0;       ///< index on the server's surface: ties at edges go to the lower
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit outward normal at rest
  std::array<int, 3> neighbours{-1, -1, -1};         ///< patch triangle across edge (k, k+1), or -1
  /// The whole surface's pseudo-normal at edge (k, k+1), inside the patch or at its rim:
  /// with it the sign of a point nearest an edge is the whole surface's.
  std::array<Eigen::Vector3d, 3> edge_normals{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                              Eigen::Vector3d::Zero()};
};

/// A surface triangle bordering the patch: geometry only (no force), so that the client can
/// tell a tool beyond the patch's rim (beside the object, or over an untouchable region).
struct IrGuardTriangle {
  std::array<Eigen::Vector3d, 3> corners{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                         Eigen::Vector3d::Zero()};
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

struct IrRemoteContact {
  int user = 0;                ///< the other user's slot
  std::array<int, 3> nodes{};  ///< local node indices of their nearest triangle
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  /// The whole surface's pseudo-normals at the triangle's edges (k, k+1) and vertices,
  /// to tell whether the remote tool presses.
  std::array<Eigen::Vector3d, 3> edge_normals{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                              Eigen::Vector3d::Zero()};
  std::array<Eigen::Vector3d, 3> vertex_normals{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                                Eigen::Vector3d::Zero()};
  double tool_radius = 0;  ///< [m]
};

/// Asymmetry tolerated in a received matrix that must be symmetric (M_CC, W), relative to
/// its largest entry: round-off of another producer's arithmetic, far below any physical meaning.
inline constexpr double kMaxRelativeAsymmetry = 1e-9;

/// The sphere contact model's part of a condensed FEM body (common/contact/sphere_contact.h),
/// instead of M~ and u_B: every row node is a candidate, pushed along its own inward normal
/// by the sphere (own or remote) with the least gap to it, or, an obstacle row, along a
/// rigid obstacle's normal by that obstacle, with a gap that does not depend on the tools.
/// With B held where it is, W is the compliance between the row nodes' pushes and q0 their
/// displacement along their directions under no push, so that under pushes lambda a node's
/// clearance is g + q0 + (W lambda); neither depends on where the tools are. B itself
/// travels only as its tags.
struct SphereContactIr {
  Eigen::Matrix3Xd
      normals;  ///< per row node: its push's unit direction, zero for a node the model cannot hold
  Eigen::VectorXd free_clearance;  ///< q0 per row node [m]
  /// W, row nodes square, symmetric [m/N]; the rows and columns of a node the model cannot
  /// hold are zero.
  Eigen::MatrixXd normal_compliance;
  /// Per row node: the gap at rest [m] to the rigid obstacle that holds it, along its normal
  /// (then the obstacle's), or +inf for a node the spheres hold (sphere_contact.h).
  Eigen::VectorXd obstacle_gaps;
  std::vector<int>
      contacts;  ///< row nodes the server's state pushes (ascending): the first tick's set
  std::vector<std::int64_t> held_node_ids;  ///< B's tags: the nodes W and q0 hold where they are
};

struct CondensedFemIr {
  ContactModel contact_model = ContactModel::node_translation;
  IrPrecision precision = IrPrecision::f64;

  std::vector<std::int64_t> node_ids;  ///< mesh node tags, per local node
  std::vector<AxisMask> fixed_axes;    ///< per local node
  Eigen::Matrix3Xd rest_positions;     ///< [m], per contact (row) node
  int patch_node_count = 0;
  int row_node_count = 0;

  std::vector<IrTriangle> patch;  ///< own patch; patch[0] is the triangle nearest the tool
  Eigen::Matrix3Xd
      patch_vertex_normals;  ///< per patch node: the whole surface's angle-weighted normal
  std::vector<IrGuardTriangle> guard;  ///< the ring of surface triangles around the patch
  std::vector<IrRemoteContact> remotes;

  Eigen::MatrixXd m_tilde;  ///< rows: free dofs of C; columns: free dofs of all nodes [N/m]
  Eigen::VectorXd boundary_displacement;  ///< u_B, free dofs of B [m]
  /// f_rest, per free dof of C, or empty (none): loads the body carries besides the tools
  /// and B act on C as f = M~ (u_C, u_B) + f_rest. An FEM pair's front: the support of the
  /// body behind it closing the gaps its pushing nodes had at rest [N]. Always in f64.
  Eigen::VectorXd rest_forces;
  /// Sent instead of M~ (then empty) to a client that condenses itself (compliance_rows.h);
  /// the client's ClientCondensation fills M~ from them and clears them.
  std::optional<ComplianceRows> compliance_rows;
  /// B truncation: the held nodes the IR leaves out (their columns of M~ and u_B), tags and
  /// fixed axes. M~ needs none of them, but a client that condenses itself must hold their
  /// compliance too (M_CC condenses over all of B), so they travel with compliance rows
  /// only; the nodes past row_node_count are the held nodes kept, as the server chose them.
  std::vector<std::int64_t> truncated_node_ids;
  std::vector<AxisMask> truncated_fixed_axes;
  /// Under the sphere contact model (and only then): its part, instead of M~ and u_B (both
  /// empty; node_ids are the row nodes alone).
  std::optional<SphereContactIr> sphere;

  int node_count() const { return static_cast<int>(node_ids.size()); }
  /// The nodes a client condensing itself holds after this IR: node_ids, then truncated_node_ids.
  std::vector<std::int64_t> held_node_ids() const;
  /// Bytes of the content as sent: geometry, M~ and u_B at the stored precision.
  std::size_t size_bytes() const;
};

/// What a client is sent of a body: one alternative per body kind
/// (common/kinds/body_kinds.h); the wire's `oneof body` mirrors it.
using IrBody =
    PerKind<ForKind<LinearElasticKind, CondensedFemIr>, ForKind<MassSpringKind, MassSpringIr>,
            ForKind<HomeSpringKind, HomeSpringPatch>,
            ForKind<SeparationKind, SeparationIr>>::variant;

struct IntermediateRepresentation {
  /// 2: the envelope and a body of one kind (1 was the condensed FEM body's fields alone);
  /// 3: a condensed FEM body may come as compliance rows instead of M~;
  /// 4: compliance rows may name held nodes that B truncation leaves out (still reads 2, 3);
  /// 5: a condensed FEM body may carry rest forces (still reads 2 to 4);
  /// 6: under the sphere contact model it carries its normal compliance instead of M~ (still
  /// reads 2 to 5, but for sphere bodies, whose earlier form it refuses);
  /// 7: a sphere body may carry obstacle rows (still reads 2 to 6; a sphere body of 6 has none).
  static constexpr std::uint32_t kFormatVersion = 7;
  static constexpr std::uint32_t kOldestReadableVersion = 2;

  std::uint64_t epoch = 0;     ///< increases with every IR built for this user
  double simulation_time = 0;  ///< [s] of the state it was built from
  int user = 0;
  int object = 0;          ///< the scene object (body) it describes
  double tool_radius = 0;  ///< own tool [m], 0 for a point
  double force_limit = 0;  ///< [N], the scene's haptic limit
  IrBody body;

  /// Bytes of the content as sent: the envelope and the body.
  std::size_t size_bytes() const;
};

/// The IR's body as a condensed FEM body; throws Error naming the user when it is another
/// kind. For tools and tests that work on FEM bodies, not for the haptic path.
const CondensedFemIr& condensed_fem(const IntermediateRepresentation& ir);
CondensedFemIr& condensed_fem(IntermediateRepresentation& ir);

/// The remote tools the body's evaluation takes: how many, and the user slot of the i-th
/// (0 <= i < remote_count). For the haptic path: no allocation, no exception.
int remote_count(const IntermediateRepresentation& ir) noexcept;
int remote_user(const IntermediateRepresentation& ir, int i) noexcept;

/// Free dofs of local nodes [first, last) of `ir`, as (local node, axis) pairs flattened
/// to 3 * node + axis.
std::vector<int> ir_dofs(const CondensedFemIr& ir, int first_node, int last_node);

}  // namespace cohaptic
