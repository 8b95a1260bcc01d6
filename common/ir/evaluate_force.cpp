#include "common/ir/evaluate_force.h"

#include <Eigen/Cholesky>
#include "common/ir/contact_solve.h"
#include <Eigen/Geometry>
#include <fmt/format.h>

#include <cmath>
#include <utility>

#include "common/condense/naive_condensation.h"
#include "common/contact/closest_point_on_triangle.h"
#include "common/contact/nearest_triangle_rule.h"
#include "common/contact/surface_distance.h"
#include "common/ir/evaluate_sphere_contact.h"
#include "common/ir/separation_evaluation.h"
#include "common/util/error.h"
#include "common/util/overloaded.h"

namespace cohaptic {
namespace {

// One pressing tool during a tick.
struct PressingTool {
  std::array<int, 3> nodes{};  // local node indices
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();
  Eigen::Vector3d displacement = Eigen::Vector3d::Zero();
};

// Nearest patch triangle to p, and the signed height of p above the surface there: the
// pseudo-normal of the nearest feature of the patch and its guard ring.
struct PatchPoint {
  int triangle = -1;
  TriangleClosestPoint closest;
  double height = 0;       // > 0 outside the object
  bool on_border = false;  // nearest the patch's rim or beyond it
};

PatchPoint nearest_on_patch(const CondensedFemIr& ir, const PreparedFem& prepared,
                            const Eigen::Vector3d& p) {
  PatchPoint best;
  NearestTriangleRule rule;  // on the patch's surface indices: the server's choice (find_contact.h)
  for (int t = 0; t < static_cast<int>(ir.patch.size()); ++t) {
    const IrTriangle& tri = ir.patch[t];
    const TriangleClosestPoint q = closest_point_on_triangle(p, ir.rest_positions.col(tri.nodes[0]),
                                                             ir.rest_positions.col(tri.nodes[1]),
                                                             ir.rest_positions.col(tri.nodes[2]));
    if (rule.offer((p - q.point).squaredNorm(), (p - q.point).dot(tri.normal), tri.surface_index)) {
      best.triangle = t;
      best.closest = q;
    }
  }
  const IrTriangle& tri = ir.patch[best.triangle];
  const TriangleFeature feature = feature_of(best.closest.weights);
  Eigen::Vector3d normal = tri.normal;
  if (feature.kind == TriangleFeature::Kind::edge) {
    normal = tri.edge_normals[feature.index];
    best.on_border = tri.neighbours[feature.index] < 0;
  } else if (feature.kind == TriangleFeature::Kind::vertex) {
    normal = ir.patch_vertex_normals.col(tri.nodes[feature.index]);
    best.on_border = prepared.on_patch_border[tri.nodes[feature.index]];
  }
  best.height = (p - best.closest.point).dot(normal);

  // Beyond the rim the guard ring decides the side, with its faces' normals.
  double guard_distance2 = rule.distance2();
  for (const IrGuardTriangle& guard : ir.guard) {
    const TriangleClosestPoint q =
        closest_point_on_triangle(p, guard.corners[0], guard.corners[1], guard.corners[2]);
    const double d2 = (p - q.point).squaredNorm();
    if (strictly_nearer(d2, guard_distance2)) {
      guard_distance2 = d2;
      best.height = (p - q.point).dot(guard.normal);
      best.on_border = true;
    }
  }
  return best;
}

// The checks every condensed FEM body passes: its nodes, patch, remotes and geometry.
void check_fem_geometry(const CondensedFemIr& ir) {
  const int rows = ir.row_node_count;
  if (ir.node_count() < rows || rows < ir.patch_node_count || ir.patch.empty() ||
      static_cast<int>(ir.fixed_axes.size()) != ir.node_count() || ir.rest_positions.cols() != rows)
    throw Error("intermediate representation: inconsistent node counts");
  if (!ir.rest_positions.allFinite()) throw Error("intermediate representation: non-finite values");
  for (const IrTriangle& tri : ir.patch)
    for (int k = 0; k < 3; ++k)
      if (tri.nodes[k] < 0 || tri.nodes[k] >= ir.patch_node_count ||
          tri.neighbours[k] >= static_cast<int>(ir.patch.size()))
        throw Error(
            "intermediate representation: a patch triangle refers to a node or triangle outside "
            "the patch");
  if (static_cast<int>(ir.remotes.size()) >= kMaxUsers)
    throw Error(fmt::format("intermediate representation: {} remote users, at most {} supported",
                            ir.remotes.size(), kMaxUsers - 1));
  for (const IrRemoteContact& remote : ir.remotes)
    for (int node : remote.nodes)
      if (node < 0 || node >= rows)
        throw Error("intermediate representation: a remote contact refers to a non-contact node");
  if (ir.patch_vertex_normals.cols() != ir.patch_node_count || !ir.patch_vertex_normals.allFinite())
    throw Error("intermediate representation: patch vertex normals missing or not finite");
}

// M~ checked, and L~ and u0 from it.
void prepare_m_tilde(const CondensedFemIr& ir, PreparedFem& prepared, double& condition_estimate) {
  const int rows = ir.row_node_count;
  if (ir.compliance_rows)
    throw Error(
        "intermediate representation: it carries compliance rows, not M~ (a ClientCondensation "
        "completes it first)");
  if (ir.sphere)
    throw Error("intermediate representation: a sphere contact part under another contact model");
  const std::vector<int> row_dofs = ir_dofs(ir, 0, rows);
  const std::vector<int> boundary_dofs = ir_dofs(ir, rows, ir.node_count());
  const auto x = static_cast<Eigen::Index>(row_dofs.size());
  const auto b = static_cast<Eigen::Index>(boundary_dofs.size());
  if (ir.m_tilde.rows() != x || ir.m_tilde.cols() != x + b || ir.boundary_displacement.size() != b)
    throw Error(fmt::format(
        "intermediate representation: M~ is {}x{} and u_B {} long, expected {}x{} and {}",
        ir.m_tilde.rows(), ir.m_tilde.cols(), ir.boundary_displacement.size(), x, x + b, b));
  if (ir.rest_forces.size() != 0 && ir.rest_forces.size() != x)
    throw Error(fmt::format("intermediate representation: {} rest forces for {} contact dofs",
                            ir.rest_forces.size(), x));
  if (!ir.m_tilde.allFinite() || !ir.boundary_displacement.allFinite() ||
      !ir.rest_forces.allFinite())
    throw Error("intermediate representation: non-finite values");

  // M_CC is symmetric as every server builds it (to round-off at most): an asymmetric one
  // is refused, not silently replaced by its symmetric part.
  const auto sent_m_cc = ir.m_tilde.leftCols(x);
  const double asymmetry = x > 0 ? (sent_m_cc - sent_m_cc.transpose()).cwiseAbs().maxCoeff() : 0.0;
  const double scale = x > 0 ? sent_m_cc.cwiseAbs().maxCoeff() : 0.0;
  if (asymmetry > kMaxRelativeAsymmetry * scale)
    throw Error(fmt::format(
        "intermediate representation: M_CC is not symmetric (|M - M^T| up to {:g}, |M| up to {:g})",
        asymmetry, scale));
  const Eigen::MatrixXd m_cc = 0.5 * (sent_m_cc + sent_m_cc.transpose());
  const Eigen::LLT<Eigen::MatrixXd> llt(m_cc);
  if (llt.info() != Eigen::Success)
    throw Error("intermediate representation: M_CC is not positive definite");
  prepared.compliance = llt.solve(Eigen::MatrixXd::Identity(x, x));
  prepared.compliance = 0.5 * (prepared.compliance + prepared.compliance.transpose()).eval();
  // Unloaded by the tools, C carries no force: M_CC u0 + M_CB u_B + f_rest = 0.
  Eigen::VectorXd held_load = ir.m_tilde.rightCols(b) * ir.boundary_displacement;
  if (ir.rest_forces.size() != 0) held_load += ir.rest_forces;
  prepared.free_displacement = -prepared.compliance * held_load;
  condition_estimate = cholesky_condition_estimate(llt.matrixL());

  prepared.dof_index.assign(static_cast<std::size_t>(rows), {-1, -1, -1});
  for (int i = 0; i < static_cast<int>(row_dofs.size()); ++i)
    prepared.dof_index[row_dofs[i] / 3][row_dofs[i] % 3] = i;
}

PreparedFem prepare_condensed_fem(const CondensedFemIr& ir, double tool_radius,
                                  double& condition_estimate) {
  check_fem_geometry(ir);
  PreparedFem prepared;
  if (ir.contact_model == ContactModel::sphere)
    prepared.sphere = prepare_sphere_contact(ir, tool_radius, condition_estimate);
  else
    prepare_m_tilde(ir, prepared, condition_estimate);
  prepared.on_patch_border.assign(static_cast<std::size_t>(ir.patch_node_count), false);
  for (const IrTriangle& tri : ir.patch)
    for (int k = 0; k < 3; ++k)
      if (tri.neighbours[k] < 0)
        prepared.on_patch_border[tri.nodes[k]] = prepared.on_patch_border[tri.nodes[(k + 1) % 3]] =
            true;
  return prepared;
}

// The condensed FEM body's force: `envelope` holds the tool radius and the force limit.
ForceSample evaluate_condensed_fem(const IntermediateRepresentation& envelope,
                                   const CondensedFemIr& ir, const PreparedFem& prepared,
                                   const Eigen::Vector3d& own_tool,
                                   std::span<const Eigen::Vector3d> remote_tools) noexcept {
  ForceSample sample;
  if (!own_tool.allFinite()) {
    sample.flags |= kNonFinite;
    return sample;
  }

  // 1. The own tool against its patch.
  const PatchPoint own = nearest_on_patch(ir, prepared, own_tool);
  const IrTriangle& own_triangle = ir.patch[own.triangle];
  sample.triangle = own.triangle;
  if (own.on_border) sample.flags |= kOutsidePatch;
  if (!(own.height < envelope.tool_radius)) return sample;
  sample.flags |= kInContact;

  std::array<PressingTool, kMaxUsers> pressing;
  int pressing_count = 1;
  pressing[0].nodes = own_triangle.nodes;
  pressing[0].weights = own.closest.weights;
  pressing[0].displacement =
      own_tool - envelope.tool_radius * own_triangle.normal - own.closest.point;
  sample.depth = -pressing[0].displacement.dot(own_triangle.normal);

  // 2. Remote tools against their triangles; an unpressed remote's nodes stay unloaded.
  for (std::size_t r = 0; r < ir.remotes.size() && r < remote_tools.size(); ++r) {
    const IrRemoteContact& remote = ir.remotes[r];
    const Eigen::Vector3d& p = remote_tools[r];
    if (!p.allFinite()) continue;
    const TriangleClosestPoint q = closest_point_on_triangle(
        p, ir.rest_positions.col(remote.nodes[0]), ir.rest_positions.col(remote.nodes[1]),
        ir.rest_positions.col(remote.nodes[2]));
    const TriangleFeature feature = feature_of(q.weights);
    const Eigen::Vector3d& sign_normal =
        feature.kind == TriangleFeature::Kind::edge     ? remote.edge_normals[feature.index]
        : feature.kind == TriangleFeature::Kind::vertex ? remote.vertex_normals[feature.index]
                                                        : remote.normal;
    if (!((p - q.point).dot(sign_normal) < remote.tool_radius)) continue;
    bool overlaps =
        false;  // with the own tool's triangle or an earlier remote's: a node follows one tool
    for (int t = 0; t < pressing_count; ++t)
      overlaps |= share_a_node(remote.nodes, pressing[t].nodes);
    if (overlaps) {
      sample.flags |= kRemoteOverlap;
      continue;
    }
    if (pressing_count == kMaxUsers) {
      sample.flags |= kTooManyRemotes;
      break;
    }
    pressing[pressing_count].nodes = remote.nodes;
    pressing[pressing_count].weights = q.weights;
    pressing[pressing_count].displacement = p - remote.tool_radius * remote.normal - q.point;
    ++pressing_count;
  }

  // 3. The system over Z, the free dofs of the pressing tools' triangles.
  std::array<int, kMaxContactDofs> z_row{};  // row in L~
  std::array<ContactDof, kMaxContactDofs> z_dofs{};
  std::array<Eigen::Vector3d, kMaxUsers> displacement{};
  int z = 0;
  for (int t = 0; t < pressing_count; ++t) {
    displacement[t] = pressing[t].displacement;
    for (int i = 0; i < 3; ++i)
      for (int axis = 0; axis < 3; ++axis) {
        const int row = prepared.dof_index[pressing[t].nodes[i]][axis];
        if (row < 0) continue;
        z_row[z] = row;
        z_dofs[z] = {t, axis, pressing[t].weights[i]};
        ++z;
      }
  }
  SmallMatrix l_zz(z, z);
  SmallVector u0(z);
  for (int i = 0; i < z; ++i) {
    u0[i] = prepared.free_displacement[z_row[i]];
    for (int j = 0; j < z; ++j) l_zz(i, j) = prepared.compliance(z_row[i], z_row[j]);
  }
  SmallVector nodal_forces;
  std::array<Eigen::Vector3d, kMaxUsers> tool_forces{};
  const bool solved = solve_contact_forces(
      ir.contact_model, l_zz, u0, std::span(z_dofs.data(), static_cast<std::size_t>(z)),
      std::span(displacement.data(), static_cast<std::size_t>(pressing_count)), nodal_forces,
      std::span(tool_forces.data(), static_cast<std::size_t>(pressing_count)));
  const Eigen::Vector3d contact_force = tool_forces[0];

  // 4. Safety: never a non-finite or unbounded force.
  sample.force = -contact_force;
  limit_force(sample, solved, envelope.force_limit);
  return sample;
}

ForceSample evaluate_mass_spring(const IntermediateRepresentation& envelope, const MassSpringIr& ir,
                                 const PreparedMassSpring& prepared, MassSpringPatchState& state,
                                 const Eigen::Vector3d& own_tool,
                                 std::span<const Eigen::Vector3d> remote_tools,
                                 double dt) noexcept {
  const NetworkToolReaction reaction =
      advance_mass_spring(ir, prepared, state, own_tool, envelope.tool_radius, remote_tools, dt);
  ForceSample sample;
  sample.force = reaction.force;
  sample.depth = reaction.depth;
  if (reaction.colliding) sample.flags |= kInContact;
  if (remote_tools.size() + 1 > static_cast<std::size_t>(kMaxNetworkTools))
    sample.flags |= kTooManyRemotes;
  limit_force(sample, state.network.positions.allFinite(), envelope.force_limit);
  return sample;
}

ForceSample evaluate_home_spring_body(const IntermediateRepresentation& envelope,
                                      const PreparedHomeSpringPatch& prepared, MovingVertex& moving,
                                      const Eigen::Vector3d& own_tool, double dt) noexcept {
  const HomeSpringContact contact = evaluate_viscous_home_spring(prepared, moving, own_tool, dt);
  ForceSample sample;
  sample.force = contact.force;
  if (contact.touching) {
    sample.flags |= kInContact;
    sample.depth = contact.displacement.norm();
  }
  limit_force(sample, own_tool.allFinite(), envelope.force_limit);
  return sample;
}

// Prepares the IR's body by its kind.
struct BodyPreparer {
  double tool_radius;
  double& condition_estimate;
  PreparedBody operator()(const CondensedFemIr& fem) const {
    return prepare_condensed_fem(fem, tool_radius, condition_estimate);
  }
  PreparedBody operator()(const MassSpringIr& network) const {
    return prepare_mass_spring(network);
  }
  PreparedBody operator()(const HomeSpringPatch& patch) const {
    return prepare_home_spring_patch(patch);
  }
  PreparedBody operator()(const SeparationIr& separation) const {
    validate_separation_ir(separation);
    return PreparedSeparation{};
  }
};

}  // namespace

void limit_force(ForceSample& sample, bool evaluated, double force_limit) noexcept {
  if (!evaluated || !sample.force.allFinite()) {
    sample.force.setZero();
    sample.flags |= kNonFinite;
  } else if (const double magnitude = sample.force.norm(); magnitude > force_limit) {
    sample.force *= force_limit / magnitude;
    sample.flags |= kClamped;
  }
}

PreparedIR prepare_ir(IntermediateRepresentation ir) {
  PreparedIR prepared;
  if (!(std::isfinite(ir.tool_radius) && ir.tool_radius >= 0) || !(ir.force_limit >= 0))
    throw Error("intermediate representation: tool radius or force limit out of range");
  prepared.body = std::visit(BodyPreparer{ir.tool_radius, prepared.condition_estimate}, ir.body);
  prepared.ir = std::move(ir);
  return prepared;
}

EvaluationState make_evaluation_state(const PreparedIR& prepared) {
  // prepare_ir made prepared.body of the IR body's kind: std::get cannot throw here.
  return {std::visit(
      Overloaded{[&](const CondensedFemIr& fem) -> EvaluationBody {
                   FemEvaluation evaluation;
                   if (fem.contact_model == ContactModel::sphere)
                     evaluation.sphere = make_sphere_contact_state(
                         std::get<PreparedFem>(prepared.body).sphere, fem.row_node_count);
                   return evaluation;
                 },
                 [&](const MassSpringIr& network) -> EvaluationBody {
                   return make_mass_spring_state(network,
                                                 std::get<PreparedMassSpring>(prepared.body));
                 },
                 [](const HomeSpringPatch& patch) -> EvaluationBody {
                   return HomeSpringEvaluation{patch.damping > 0, false, {}};
                 },
                 [](const SeparationIr& separation) -> EvaluationBody {
                   return SeparationEvaluation{separation.state, separation.tool_state};
                 }},
      prepared.ir.body)};
}

bool evaluation_measures_elapsed_time(const EvaluationState& state) {
  const auto* tissue = std::get_if<HomeSpringEvaluation>(&state.body);
  return tissue && tissue->viscous;
}

bool evaluation_moves_the_body(const EvaluationState& state) {
  return std::visit(Overloaded{[](const FemEvaluation&) { return false; },
                               [](const MassSpringPatchState&) { return true; },
                               [](const HomeSpringEvaluation& tissue) { return tissue.viscous; },
                               [](const SeparationEvaluation&) { return true; }},
                    state.body);
}

namespace {

// What one evaluation is given besides the body.
struct Tick {
  const IntermediateRepresentation& envelope;
  const Eigen::Vector3d& own_tool;
  std::span<const Eigen::Vector3d> remote_tools;
  double dt;
  std::uint32_t buttons;
};

// One evaluation per body kind: a kind without its overload fails to compile in
// evaluate_if_of_kind below.
ForceSample evaluate_body(const CondensedFemIr& fem, const PreparedFem& prepared,
                          FemEvaluation& evaluation, const Tick& tick) noexcept {
  if (fem.contact_model == ContactModel::sphere)
    return evaluate_sphere_contact(tick.envelope, fem, prepared,
                                   evaluation.sphere ? &*evaluation.sphere : nullptr, tick.own_tool,
                                   tick.remote_tools);
  return evaluate_condensed_fem(tick.envelope, fem, prepared, tick.own_tool, tick.remote_tools);
}

ForceSample evaluate_body(const MassSpringIr& network, const PreparedMassSpring& prepared,
                          MassSpringPatchState& state, const Tick& tick) noexcept {
  return evaluate_mass_spring(tick.envelope, network, prepared, state, tick.own_tool,
                              tick.remote_tools, tick.dt);
}

ForceSample evaluate_body(const HomeSpringPatch&, const PreparedHomeSpringPatch& prepared,
                          HomeSpringEvaluation& evaluation, const Tick& tick) noexcept {
  evaluation.started = true;
  return evaluate_home_spring_body(tick.envelope, prepared, evaluation.moving, tick.own_tool,
                                   tick.dt);
}

ForceSample evaluate_body(const SeparationIr& separation, const PreparedSeparation&,
                          SeparationEvaluation& evaluation, const Tick& tick) noexcept {
  return step_separation_force(*separation.patch, evaluation.state, evaluation.tool,
                               separation.tool, tick.own_tool, tick.buttons, tick.dt,
                               tick.envelope.force_limit);
}

// Whether the IR's body is of kind `Kind`; if so, and the prepared body and the state are of
// that kind too, `sample` is its evaluation (left as it was otherwise).
template <std::size_t Kind>
bool evaluate_if_of_kind(const PreparedIR& prepared, EvaluationState& state, const Tick& tick,
                         ForceSample& sample) noexcept {
  const auto* body = std::get_if<Kind>(&prepared.ir.body);
  if (!body) return false;
  const auto* derived = std::get_if<Kind>(&prepared.body);
  auto* evaluation = std::get_if<Kind>(&state.body);
  if (derived && evaluation) sample = evaluate_body(*body, *derived, *evaluation, tick);
  return true;
}

// get_if by index, not std::visit: nothing on the haptic path may throw.
template <std::size_t... Kinds>
ForceSample evaluate_by_kind(const PreparedIR& prepared, EvaluationState& state, const Tick& tick,
                             std::index_sequence<Kinds...>) noexcept {
  ForceSample sample;
  sample.flags = kNonFinite;  // unless a prepared body and a state of the IR body's kind
  (evaluate_if_of_kind<Kinds>(prepared, state, tick, sample) || ...);
  return sample;
}

}  // namespace

ForceSample evaluate_force(const PreparedIR& prepared, EvaluationState& state,
                           const Eigen::Vector3d& own_tool,
                           std::span<const Eigen::Vector3d> remote_tools, double dt,
                           std::uint32_t buttons) noexcept {
  return evaluate_by_kind(prepared, state, Tick{prepared.ir, own_tool, remote_tools, dt, buttons},
                          std::make_index_sequence<kBodyKindCount>{});
}

ForceSample evaluate_force_in_turn(const PreparedIR& prepared, EvaluationState& state,
                                   EvaluationCarry& carry, const Eigen::Vector3d& own_tool,
                                   std::span<const Eigen::Vector3d> remote_tools, double dt,
                                   std::uint32_t buttons) noexcept {
  auto* tissue = std::get_if<HomeSpringEvaluation>(&state.body);
  const auto* patch = std::get_if<HomeSpringPatch>(&prepared.ir.body);
  if (tissue && patch && tissue->viscous && !tissue->started &&
      carry.object == prepared.ir.object) {
    tissue->moving = carry.moving;
    carry_moving_vertex(*patch, tissue->moving);
  }
  const ForceSample sample = evaluate_force(prepared, state, own_tool, remote_tools, dt, buttons);
  carry = tissue && tissue->viscous ? EvaluationCarry{prepared.ir.object, tissue->moving}
                                    : EvaluationCarry{};
  return sample;
}

}  // namespace cohaptic
