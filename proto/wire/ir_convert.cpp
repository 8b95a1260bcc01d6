#include "proto/wire/ir_convert.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <cstdint>
#include <string>
#include <vector>

#include "common/util/error.h"
#include "proto/wire/separation_convert.h"

namespace cohaptic::wire {
namespace {

using CommonIr = cohaptic::IntermediateRepresentation;
using WireIr = IntermediateRepresentation;

template <typename... Args>
[[noreturn]] void invalid(fmt::format_string<Args...> format, Args&&... args) {
  throw cohaptic::Error("intermediate representation: " +
                        fmt::format(format, std::forward<Args>(args)...));
}

template <typename Field>
void add_xyz(const Eigen::Matrix3Xd& m, Field* out) {
  out->Reserve(static_cast<int>(m.size()));
  for (Eigen::Index i = 0; i < m.size(); ++i) out->AddAlreadyReserved(m.data()[i]);
}

/// `count` doubles from `values` (column-major for a matrix), as Scalar.
template <typename Scalar, typename Field>
void add_values(const double* values, Eigen::Index count, Field* out) {
  out->Reserve(static_cast<int>(count));
  for (Eigen::Index i = 0; i < count; ++i) out->AddAlreadyReserved(static_cast<Scalar>(values[i]));
}

template <typename Triples>
void add_triple(const std::array<Eigen::Vector3d, 3>& vectors, Triples* out) {
  for (const Eigen::Vector3d& v : vectors) to_wire(v, out->Add());
}

// ---- from_wire checks ----

void check_vec3(const Vec3& v, const std::string& what) {
  if (!is_finite(v))
    invalid("{} has a non-finite component ({}, {}, {})", what, v.x(), v.y(), v.z());
}

template <typename Triples>
std::array<Eigen::Vector3d, 3> read_triple(const Triples& vectors, const std::string& what) {
  if (vectors.size() != 3) invalid("{} has {} entries, expected 3", what, vectors.size());
  std::array<Eigen::Vector3d, 3> out;
  for (int k = 0; k < 3; ++k) {
    check_vec3(vectors[k], fmt::format("{}[{}]", what, k));
    out[static_cast<std::size_t>(k)] = from_wire(vectors[k]);
  }
  return out;
}

Eigen::Vector3d read_vec3(const Vec3& v, const std::string& what) {
  check_vec3(v, what);
  return from_wire(v);
}

/// Three node indices, each in [0, limit).
std::array<int, 3> read_nodes(const google::protobuf::RepeatedField<std::uint32_t>& nodes,
                              std::uint32_t limit, const std::string& what, const char* range) {
  if (nodes.size() != 3) invalid("{}.nodes has {} entries, expected 3", what, nodes.size());
  std::array<int, 3> out{};
  for (int k = 0; k < 3; ++k) {
    if (nodes[k] >= limit)
      invalid("{}.nodes[{}] = {} is outside the {} ({} nodes)", what, k, nodes[k], range, limit);
    out[static_cast<std::size_t>(k)] = static_cast<int>(nodes[k]);
  }
  return out;
}

Eigen::Matrix3Xd read_xyz(const google::protobuf::RepeatedField<double>& values,
                          std::uint32_t count, const char* what) {
  if (static_cast<std::uint64_t>(values.size()) != 3ull * count)
    invalid("{} has {} values, expected 3 x {}", what, values.size(), count);
  Eigen::Matrix3Xd out(3, static_cast<Eigen::Index>(count));
  for (int i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) invalid("{}[{}] is not finite ({})", what, i, values[i]);
    out.data()[i] = values[i];
  }
  return out;
}

int to_int(std::uint32_t value, const char* what) {
  if (value > static_cast<std::uint32_t>(INT_MAX)) invalid("{} = {} is out of range", what, value);
  return static_cast<int>(value);
}

std::size_t free_dofs(const std::string& fixed_axes, std::size_t first, std::size_t last) {
  std::size_t count = 0;
  for (std::size_t i = first; i < last; ++i)
    for (int axis = 0; axis < 3; ++axis)
      count += ((static_cast<unsigned char>(fixed_axes[i]) >> axis) & 1u) ? 0u : 1u;
  return count;
}

/// One byte per node, each a mask of x, y, z (`what`: the field, for the message).
std::vector<AxisMask> read_fixed_axes(const std::string& bytes, const char* what) {
  std::vector<AxisMask> masks;
  masks.reserve(bytes.size());
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    const auto mask = static_cast<AxisMask>(bytes[i]);
    if (mask & ~kAllAxes)
      invalid("{} of node {} is 0x{:02x}, not a mask of x, y, z", what, i,
              static_cast<unsigned>(mask));
    masks.push_back(mask);
  }
  return masks;
}

/// `values` (f64 or f32 on the wire) into doubles, each finite.
template <typename Field, typename Target>
void read_values(const Field& values, Target& out, const char* what) {
  for (int i = 0; i < values.size(); ++i) {
    const double v = static_cast<double>(values[i]);
    if (!std::isfinite(v)) invalid("{}[{}] is not finite ({})", what, i, v);
    out.data()[i] = v;
  }
}

}  // namespace

namespace {

void sphere_to_wire(const SphereContactIr& sphere, IrPrecision precision, SphereContact* out) {
  add_xyz(sphere.normals, out->mutable_normals());
  add_values<double>(sphere.free_clearance.data(), sphere.free_clearance.size(),
                     out->mutable_free_clearance());
  const Eigen::MatrixXd& w = sphere.normal_compliance;
  const auto add_upper = [&](auto* field) {
    field->Reserve(static_cast<int>(w.rows() * (w.rows() + 1) / 2));
    for (Eigen::Index j = 0; j < w.cols(); ++j)
      for (Eigen::Index i = 0; i <= j; ++i)
        field->AddAlreadyReserved(
            static_cast<typename std::decay_t<decltype(*field)>::value_type>(w(i, j)));
  };
  if (precision == IrPrecision::f32)
    add_upper(out->mutable_normal_compliance_f32());
  else
    add_upper(out->mutable_normal_compliance_f64());
  for (int node : sphere.contacts) out->add_contacts(static_cast<std::uint32_t>(node));
  out->mutable_held_node_ids()->Add(sphere.held_node_ids.begin(), sphere.held_node_ids.end());
  for (Eigen::Index i = 0; i < sphere.obstacle_gaps.size(); ++i)
    if (std::isfinite(sphere.obstacle_gaps[i])) {
      out->add_obstacle_rows(static_cast<std::uint32_t>(i));
      out->add_obstacle_gaps(sphere.obstacle_gaps[i]);
    }
}

void fem_to_wire(const CondensedFemIr& ir, CondensedFem* out) {
  out->set_contact_model(ir.contact_model == ContactModel::point_constraint ? CondensedFem::POINT
                         : ir.contact_model == ContactModel::sphere         ? CondensedFem::SPHERE
                                                                    : CondensedFem::TRANSLATION);
  out->mutable_node_ids()->Reserve(static_cast<int>(ir.node_ids.size()));
  for (std::int64_t id : ir.node_ids) out->mutable_node_ids()->AddAlreadyReserved(id);
  out->set_fixed_axes(std::string(ir.fixed_axes.begin(), ir.fixed_axes.end()));
  add_xyz(ir.rest_positions, out->mutable_rest_positions());
  out->set_patch_node_count(static_cast<std::uint32_t>(ir.patch_node_count));
  out->set_row_node_count(static_cast<std::uint32_t>(ir.row_node_count));
  for (const cohaptic::IrTriangle& tri : ir.patch) {
    wire::IrTriangle* t = out->add_patch();
    for (int node : tri.nodes) t->add_nodes(static_cast<std::uint32_t>(node));
    t->set_surface_index(tri.surface_index);
    to_wire(tri.normal, t->mutable_normal());
    for (int neighbour : tri.neighbours) t->add_neighbours(neighbour);
    add_triple(tri.edge_normals, t->mutable_edge_normals());
  }
  add_xyz(ir.patch_vertex_normals, out->mutable_patch_vertex_normals());
  for (const cohaptic::IrGuardTriangle& guard : ir.guard) {
    wire::IrGuardTriangle* g = out->add_guard();
    add_triple(guard.corners, g->mutable_corners());
    to_wire(guard.normal, g->mutable_normal());
  }
  for (const cohaptic::IrRemoteContact& remote : ir.remotes) {
    wire::IrRemoteContact* r = out->add_remotes();
    r->set_user(static_cast<std::uint32_t>(remote.user));
    for (int node : remote.nodes) r->add_nodes(static_cast<std::uint32_t>(node));
    to_wire(remote.normal, r->mutable_normal());
    add_triple(remote.edge_normals, r->mutable_edge_normals());
    add_triple(remote.vertex_normals, r->mutable_vertex_normals());
    r->set_tool_radius(remote.tool_radius);
  }
  if (ir.compliance_rows) {
    const Eigen::MatrixXd& rows = ir.compliance_rows->rows;
    out->set_m_rows(static_cast<std::uint32_t>(ir_dofs(ir, 0, ir.row_node_count).size()));
    out->set_m_cols(static_cast<std::uint32_t>(ir_dofs(ir, 0, ir.node_count()).size()));
    out->mutable_truncated_node_ids()->Add(ir.truncated_node_ids.begin(),
                                           ir.truncated_node_ids.end());
    out->set_truncated_fixed_axes(
        std::string(ir.truncated_fixed_axes.begin(), ir.truncated_fixed_axes.end()));
    out->set_rows_generation(ir.compliance_rows->generation);
    out->set_compliance_row_count(static_cast<std::uint32_t>(rows.rows()));
    add_values<double>(rows.data(), rows.size(), out->mutable_compliance_rows());
  } else {
    out->set_m_rows(static_cast<std::uint32_t>(ir.m_tilde.rows()));
    out->set_m_cols(static_cast<std::uint32_t>(ir.m_tilde.cols()));
  }
  if (ir.precision == IrPrecision::f32) {
    add_values<float>(ir.m_tilde.data(), ir.m_tilde.size(), out->mutable_m_tilde_f32());
    add_values<float>(ir.boundary_displacement.data(), ir.boundary_displacement.size(),
                      out->mutable_boundary_displacement_f32());
  } else {
    add_values<double>(ir.m_tilde.data(), ir.m_tilde.size(), out->mutable_m_tilde_f64());
    add_values<double>(ir.boundary_displacement.data(), ir.boundary_displacement.size(),
                       out->mutable_boundary_displacement_f64());
  }
  add_values<double>(ir.rest_forces.data(), ir.rest_forces.size(), out->mutable_rest_forces());
  if (ir.sphere) sphere_to_wire(*ir.sphere, ir.precision, out->mutable_sphere());
}

void mass_spring_to_wire(const MassSpringIr& ir, MassSpringPatch* out) {
  out->mutable_node_ids()->Add(ir.node_ids.begin(), ir.node_ids.end());
  add_xyz(ir.positions, out->mutable_positions());
  add_xyz(ir.velocities, out->mutable_velocities());
  add_values<double>(ir.mass.data(), ir.mass.size(), out->mutable_masses());
  out->set_held(std::string(ir.held.begin(), ir.held.end()));
  for (const Spring& spring : ir.springs) {
    out->add_spring_nodes(static_cast<std::uint32_t>(spring.a));
    out->add_spring_nodes(static_cast<std::uint32_t>(spring.b));
    out->add_spring_rest_lengths(spring.rest_length);
    out->add_spring_stiffness(spring.stiffness);
    out->add_spring_damping(spring.damping);
  }
  for (const auto& triangle : ir.triangles)
    for (int node : triangle) out->add_triangles(static_cast<std::uint32_t>(node));
  const MassSpringParameters& p = ir.parameters;
  to_wire(p.gravity, out->mutable_gravity());
  out->set_node_damping(p.node_damping);
  out->set_tool_friction(p.tool_friction);
  out->set_time_step(p.time_step);
  if (p.plane) {
    MassSpringPlane* plane = out->mutable_plane();
    to_wire(p.plane->point, plane->mutable_point());
    to_wire(p.plane->normal, plane->mutable_normal());
    plane->set_static_friction(p.plane->static_friction);
    plane->set_dynamic_friction(p.plane->dynamic_friction);
  }
  for (int user : ir.remote_users) out->add_remote_users(static_cast<std::uint32_t>(user));
  out->mutable_remote_radii()->Add(ir.remote_radii.begin(), ir.remote_radii.end());
  for (const ToolPress& press : ir.presses) {
    ToolPressState* state = out->add_presses();
    state->set_pressing(press.pressing);
    to_wire(press.previous, state->mutable_previous());
  }
  if (!ir.backing.empty()) {
    NodeBacking* backing = out->mutable_backing();
    for (int node : ir.backing.nodes) backing->add_nodes(static_cast<std::uint32_t>(node));
    const Eigen::MatrixXd& compliance =
        ir.backing.compliance;  // symmetric: column-major is row-major
    add_values<double>(compliance.data(), compliance.size(), backing->mutable_compliance());
    add_values<double>(ir.backing.offsets.data(), ir.backing.offsets.size(),
                       backing->mutable_offsets());
    add_values<double>(ir.backing.damping.data(), ir.backing.damping.size(),
                       backing->mutable_damping());
    add_values<double>(ir.backing.targets.data(), ir.backing.targets.size(),
                       backing->mutable_targets());
    add_values<double>(ir.backing.normals.data(), ir.backing.normals.size(),
                       backing->mutable_normals());
  }
}

void home_spring_to_wire(const cohaptic::HomeSpringPatch& patch, HomeSpringPatch* out) {
  add_xyz(patch.rest_positions, out->mutable_rest_positions());
  out->set_contact_vertex_count(static_cast<std::uint32_t>(patch.contact_vertex_count));
  for (const Triangle& triangle : patch.triangles)
    for (int vertex : triangle) out->add_triangles(static_cast<std::uint32_t>(vertex));
  for (int offset : patch.ring_offsets) out->add_ring_offsets(static_cast<std::uint32_t>(offset));
  for (int vertex : patch.ring_vertices) out->add_ring_vertices(static_cast<std::uint32_t>(vertex));
  for (int vertex : patch.surface_vertex)
    out->add_surface_vertex(static_cast<std::uint32_t>(vertex));
  out->set_home_stiffness(patch.home_stiffness);
  out->set_neighbour_stiffness(patch.neighbour_stiffness);
  out->set_damping(patch.damping);
  to_wire(patch.trocar_pivot, out->mutable_trocar_pivot());
  if (patch.grasp.active()) {
    out->mutable_grasp()->set_vertex(static_cast<std::uint32_t>(patch.grasp.vertex));
    to_wire(patch.grasp.tool_at_grasp, out->mutable_grasp()->mutable_tool_at_grasp());
  }
}

// Writes the IR's body into the wire's oneof, by kind.
struct BodyToWire {
  WireIr* out;
  void operator()(const CondensedFemIr& fem) const { fem_to_wire(fem, out->mutable_fem()); }
  void operator()(const MassSpringIr& network) const {
    mass_spring_to_wire(network, out->mutable_mass_spring());
  }
  void operator()(const cohaptic::HomeSpringPatch& patch) const {
    home_spring_to_wire(patch, out->mutable_home_spring());
  }
  void operator()(const cohaptic::SeparationIr& separation) const {
    separation_to_wire(separation, out->mutable_separation());
  }
};

}  // namespace

void to_wire(const CommonIr& ir, WireIr* out) {
  out->Clear();
  out->set_format_version(CommonIr::kFormatVersion);
  out->set_epoch(ir.epoch);
  out->set_simulation_time(ir.simulation_time);
  out->set_user(static_cast<std::uint32_t>(ir.user));
  out->set_object(static_cast<std::uint32_t>(ir.object));
  out->set_tool_radius(ir.tool_radius);
  out->set_force_limit(ir.force_limit);
  std::visit(BodyToWire{out}, ir.body);
}

WireIr to_wire(const CommonIr& ir) {
  WireIr out;
  to_wire(ir, &out);
  return out;
}

namespace {

SphereContactIr sphere_from_wire(const SphereContact& w, std::uint32_t nodes,
                                 IrPrecision& precision) {
  SphereContactIr sphere;
  sphere.normals = read_xyz(w.normals(), nodes, "sphere.normals");
  if (static_cast<std::uint32_t>(w.free_clearance_size()) != nodes)
    invalid("sphere.free_clearance has {} values for {} row nodes", w.free_clearance_size(), nodes);
  sphere.free_clearance.resize(static_cast<Eigen::Index>(nodes));
  read_values(w.free_clearance(), sphere.free_clearance, "sphere.free_clearance");
  const std::uint64_t upper = std::uint64_t{nodes} * (nodes + 1) / 2;
  const bool f32 = w.normal_compliance_f32_size() > 0;
  if (f32 && w.normal_compliance_f64_size() > 0)
    invalid("sphere.normal_compliance in both f64 and f32");
  if (static_cast<std::uint64_t>(f32 ? w.normal_compliance_f32_size()
                                     : w.normal_compliance_f64_size()) != upper)
    invalid(
        "sphere.normal_compliance has {} values, expected the upper triangle of {} row nodes, {}",
        f32 ? w.normal_compliance_f32_size() : w.normal_compliance_f64_size(), nodes, upper);
  if (f32) precision = IrPrecision::f32;
  const auto n = static_cast<Eigen::Index>(nodes);
  sphere.normal_compliance.resize(n, n);
  const auto read_upper = [&](const auto& field, const char* what) {
    int k = 0;
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = 0; i <= j; ++i, ++k) {
        const auto v = static_cast<double>(field[k]);
        if (!std::isfinite(v)) invalid("{}[{}] is not finite ({})", what, k, v);
        sphere.normal_compliance(i, j) = sphere.normal_compliance(j, i) = v;
      }
  };
  if (f32)
    read_upper(w.normal_compliance_f32(), "sphere.normal_compliance_f32");
  else
    read_upper(w.normal_compliance_f64(), "sphere.normal_compliance_f64");
  for (std::uint32_t node : w.contacts()) {
    if (node >= nodes) invalid("sphere.contacts names row node {} of {}", node, nodes);
    sphere.contacts.push_back(static_cast<int>(node));
  }
  sphere.held_node_ids.assign(w.held_node_ids().begin(), w.held_node_ids().end());
  if (w.obstacle_rows_size() != w.obstacle_gaps_size())
    invalid("sphere.obstacle_rows has {} values, sphere.obstacle_gaps {}", w.obstacle_rows_size(),
            w.obstacle_gaps_size());
  sphere.obstacle_gaps = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  for (int k = 0; k < w.obstacle_rows_size(); ++k) {
    const std::uint32_t row = w.obstacle_rows(k);
    if (row >= nodes || (k > 0 && row <= w.obstacle_rows(k - 1)))
      invalid("sphere.obstacle_rows[{}] = {} is not an ascending row node of {}", k, row, nodes);
    if (!std::isfinite(w.obstacle_gaps(k)))
      invalid("sphere.obstacle_gaps[{}] is not finite ({})", k, w.obstacle_gaps(k));
    sphere.obstacle_gaps[row] = w.obstacle_gaps(k);
  }
  return sphere;
}

CondensedFemIr fem_from_wire(const CondensedFem& w) {
  CondensedFemIr ir;
  switch (w.contact_model()) {
    case CondensedFem::TRANSLATION:
      ir.contact_model = ContactModel::node_translation;
      break;
    case CondensedFem::POINT:
      ir.contact_model = ContactModel::point_constraint;
      break;
    case CondensedFem::SPHERE:
      ir.contact_model = ContactModel::sphere;
      break;
    default:
      invalid("unknown contact model {}", static_cast<int>(w.contact_model()));
  }

  // Nodes.
  const auto nodes = static_cast<std::uint32_t>(w.node_ids_size());
  if (w.fixed_axes().size() != nodes)
    invalid("{} fixed_axes bytes for {} nodes", w.fixed_axes().size(), nodes);
  if (w.row_node_count() > nodes)
    invalid("row_node_count {} exceeds the {} nodes", w.row_node_count(), nodes);
  if (w.patch_node_count() > w.row_node_count())
    invalid("patch_node_count {} exceeds row_node_count {}", w.patch_node_count(),
            w.row_node_count());
  ir.node_ids.assign(w.node_ids().begin(), w.node_ids().end());
  ir.fixed_axes = read_fixed_axes(w.fixed_axes(), "fixed_axes");
  ir.row_node_count = static_cast<int>(w.row_node_count());
  ir.patch_node_count = static_cast<int>(w.patch_node_count());
  ir.rest_positions = read_xyz(w.rest_positions(), w.row_node_count(), "rest_positions");

  // Patch.
  if (w.patch_size() == 0) invalid("the patch has no triangle");
  for (int i = 0; i < w.patch_size(); ++i) {
    const wire::IrTriangle& t = w.patch(i);
    const std::string what = fmt::format("patch[{}]", i);
    cohaptic::IrTriangle tri;
    tri.nodes = read_nodes(t.nodes(), w.patch_node_count(), what, "patch");
    if (t.surface_index() < 0)
      invalid("{}.surface_index is negative ({})", what, t.surface_index());
    tri.surface_index = t.surface_index();
    tri.normal = read_vec3(t.normal(), what + ".normal");
    if (t.neighbours_size() != 3)
      invalid("{}.neighbours has {} entries, expected 3", what, t.neighbours_size());
    for (int k = 0; k < 3; ++k) {
      const std::int32_t n = t.neighbours(k);
      if (n < -1 || n >= w.patch_size())
        invalid("{}.neighbours[{}] = {} is neither -1 nor one of the {} patch triangles", what, k,
                n, w.patch_size());
      tri.neighbours[static_cast<std::size_t>(k)] = n;
    }
    tri.edge_normals = read_triple(t.edge_normals(), what + ".edge_normals");
    ir.patch.push_back(tri);
  }
  ir.patch_vertex_normals =
      read_xyz(w.patch_vertex_normals(), w.patch_node_count(), "patch_vertex_normals");
  for (int i = 0; i < w.guard_size(); ++i) {
    const std::string what = fmt::format("guard[{}]", i);
    cohaptic::IrGuardTriangle guard;
    guard.corners = read_triple(w.guard(i).corners(), what + ".corners");
    guard.normal = read_vec3(w.guard(i).normal(), what + ".normal");
    ir.guard.push_back(guard);
  }
  for (int i = 0; i < w.remotes_size(); ++i) {
    const wire::IrRemoteContact& r = w.remotes(i);
    const std::string what = fmt::format("remotes[{}]", i);
    cohaptic::IrRemoteContact remote;
    remote.user = to_int(r.user(), "remote user");
    remote.nodes = read_nodes(r.nodes(), w.row_node_count(), what, "contact nodes");
    remote.normal = read_vec3(r.normal(), what + ".normal");
    remote.edge_normals = read_triple(r.edge_normals(), what + ".edge_normals");
    remote.vertex_normals = read_triple(r.vertex_normals(), what + ".vertex_normals");
    if (!(std::isfinite(r.tool_radius()) && r.tool_radius() >= 0))
      invalid("{}.tool_radius {} is not a finite length >= 0", what, r.tool_radius());
    remote.tool_radius = r.tool_radius();
    ir.remotes.push_back(remote);
  }

  if (w.has_sphere() && ir.contact_model != ContactModel::sphere)
    invalid("a sphere contact part under another contact model");
  if (ir.contact_model == ContactModel::sphere) {
    if (!w.has_sphere())
      invalid("a sphere body without its normal compliance (format 6 carries it instead of M~)");
    if (nodes != w.row_node_count() || w.m_rows() != 0 || w.m_cols() != 0 ||
        w.m_tilde_f64_size() > 0 || w.m_tilde_f32_size() > 0 ||
        w.boundary_displacement_f64_size() > 0 || w.boundary_displacement_f32_size() > 0 ||
        w.rows_generation() > 0 || w.rest_forces_size() > 0 || w.truncated_node_ids_size() > 0)
      invalid(
          "a sphere body carries its row nodes and its normal compliance only ({} nodes, {} row "
          "nodes, M~ {} x {})",
          nodes, w.row_node_count(), w.m_rows(), w.m_cols());
    ir.sphere = sphere_from_wire(w.sphere(), nodes, ir.precision);
    return ir;
  }

  // M~ and u_B: sizes follow from the free dofs of the contact and boundary nodes.
  const bool f64 = w.m_tilde_f64_size() > 0 || w.boundary_displacement_f64_size() > 0;
  const bool f32 = w.m_tilde_f32_size() > 0 || w.boundary_displacement_f32_size() > 0;
  if (f64 && f32) invalid("M~ and u_B mix f64 and f32 fields");
  ir.precision = f32 ? IrPrecision::f32 : IrPrecision::f64;
  const std::size_t row_dofs = free_dofs(w.fixed_axes(), 0, w.row_node_count());
  const std::size_t boundary_dofs = free_dofs(w.fixed_axes(), w.row_node_count(), nodes);
  if (w.m_rows() != row_dofs)
    invalid("m_rows {} differs from the {} free dofs of the contact nodes", w.m_rows(), row_dofs);
  if (w.m_cols() != row_dofs + boundary_dofs)
    invalid("m_cols {} differs from the {} free dofs of all nodes", w.m_cols(),
            row_dofs + boundary_dofs);
  const bool rows_form = w.rows_generation() > 0;
  const std::uint64_t entries = rows_form ? 0 : std::uint64_t{w.m_rows()} * w.m_cols();
  const auto m_length =
      static_cast<std::uint64_t>(f32 ? w.m_tilde_f32_size() : w.m_tilde_f64_size());
  if (m_length != entries)
    invalid("M~ has {} values, expected {} (m_rows x m_cols = {} x {}, none with compliance rows)",
            m_length, entries, w.m_rows(), w.m_cols());
  // B truncation's held nodes left out of M~: the rows' columns cover them too.
  const auto truncated = static_cast<std::uint32_t>(w.truncated_node_ids_size());
  if (!rows_form && (truncated > 0 || !w.truncated_fixed_axes().empty()))
    invalid("truncated held nodes without a rows_generation (only compliance rows carry them)");
  if (w.truncated_fixed_axes().size() != truncated)
    invalid("{} truncated_fixed_axes bytes for {} truncated held nodes",
            w.truncated_fixed_axes().size(), truncated);
  ir.truncated_node_ids.assign(w.truncated_node_ids().begin(), w.truncated_node_ids().end());
  ir.truncated_fixed_axes = read_fixed_axes(w.truncated_fixed_axes(), "truncated_fixed_axes");
  const std::uint64_t row_cols = w.m_cols() + free_dofs(w.truncated_fixed_axes(), 0, truncated);
  const std::uint64_t row_values = std::uint64_t{w.compliance_row_count()} * row_cols;
  if (!rows_form && (w.compliance_row_count() > 0 || w.compliance_rows_size() > 0))
    invalid("compliance rows without a rows_generation");
  if (static_cast<std::uint64_t>(w.compliance_rows_size()) != row_values)
    invalid(
        "compliance_rows has {} values, expected compliance_row_count x (m_cols + free dofs of the "
        "truncated "
        "held nodes) = {} x {}",
        w.compliance_rows_size(), w.compliance_row_count(), row_cols);
  const auto u_length = static_cast<std::uint64_t>(f32 ? w.boundary_displacement_f32_size()
                                                       : w.boundary_displacement_f64_size());
  if (u_length != boundary_dofs)
    invalid("u_B has {} values, expected {} (free boundary dofs)", u_length, boundary_dofs);
  ir.m_tilde.resize(rows_form ? 0 : static_cast<Eigen::Index>(w.m_rows()),
                    rows_form ? 0 : static_cast<Eigen::Index>(w.m_cols()));
  ir.boundary_displacement.resize(static_cast<Eigen::Index>(boundary_dofs));
  if (f32) {
    read_values(w.m_tilde_f32(), ir.m_tilde, "m_tilde_f32");
    read_values(w.boundary_displacement_f32(), ir.boundary_displacement,
                "boundary_displacement_f32");
  } else {
    read_values(w.m_tilde_f64(), ir.m_tilde, "m_tilde_f64");
    read_values(w.boundary_displacement_f64(), ir.boundary_displacement,
                "boundary_displacement_f64");
  }
  if (w.rest_forces_size() > 0) {
    if (static_cast<std::uint64_t>(w.rest_forces_size()) != w.m_rows())
      invalid("rest_forces has {} values, expected m_rows = {}", w.rest_forces_size(), w.m_rows());
    ir.rest_forces.resize(static_cast<Eigen::Index>(w.m_rows()));
    read_values(w.rest_forces(), ir.rest_forces, "rest_forces");
  }
  if (rows_form) {
    ComplianceRows rows{w.rows_generation(),
                        Eigen::MatrixXd(static_cast<Eigen::Index>(w.compliance_row_count()),
                                        static_cast<Eigen::Index>(row_cols))};
    read_values(w.compliance_rows(), rows.rows, "compliance_rows");
    ir.compliance_rows = std::move(rows);
  }
  return ir;
}

// Sizes and indices here; signs and physical ranges are prepare_ir's (check_network).
MassSpringIr mass_spring_from_wire(const MassSpringPatch& w) {
  MassSpringIr ir;
  const auto nodes = static_cast<std::uint32_t>(w.node_ids_size());
  ir.node_ids.assign(w.node_ids().begin(), w.node_ids().end());
  ir.positions = read_xyz(w.positions(), nodes, "positions");
  ir.velocities = read_xyz(w.velocities(), nodes, "velocities");
  if (static_cast<std::uint32_t>(w.masses_size()) != nodes)
    invalid("{} masses for {} nodes", w.masses_size(), nodes);
  ir.mass.resize(static_cast<Eigen::Index>(nodes));
  read_values(w.masses(), ir.mass, "masses");
  if (w.held().size() != nodes) invalid("{} held bytes for {} nodes", w.held().size(), nodes);
  for (char held : w.held()) {
    if (held != 0 && held != 1) invalid("a held byte is {}, not 0 or 1", static_cast<int>(held));
    ir.held.push_back(static_cast<std::uint8_t>(held));
  }
  const int springs = w.spring_rest_lengths_size();
  if (w.spring_nodes_size() != 2 * springs || w.spring_stiffness_size() != springs ||
      w.spring_damping_size() != springs)
    invalid("{} spring node indices, {} rest lengths, {} stiffnesses and {} dampings",
            w.spring_nodes_size(), springs, w.spring_stiffness_size(), w.spring_damping_size());
  for (int i = 0; i < springs; ++i) {
    Spring spring;
    for (int end = 0; end < 2; ++end) {
      const std::uint32_t node = w.spring_nodes(2 * i + end);
      if (node >= nodes) invalid("spring {} names node {} of {}", i, node, nodes);
      (end == 0 ? spring.a : spring.b) = static_cast<int>(node);
    }
    spring.rest_length = w.spring_rest_lengths(i);
    spring.stiffness = w.spring_stiffness(i);
    spring.damping = w.spring_damping(i);
    ir.springs.push_back(spring);
  }
  if (w.triangles_size() % 3 != 0)
    invalid("{} triangle indices, not a multiple of 3", w.triangles_size());
  for (int i = 0; i < w.triangles_size(); i += 3) {
    std::array<int, 3> triangle{};
    for (int k = 0; k < 3; ++k) {
      if (w.triangles(i + k) >= nodes)
        invalid("triangle {} names node {} of {}", i / 3, w.triangles(i + k), nodes);
      triangle[static_cast<std::size_t>(k)] = static_cast<int>(w.triangles(i + k));
    }
    ir.triangles.push_back(triangle);
  }
  MassSpringParameters& p = ir.parameters;
  p.gravity = read_vec3(w.gravity(), "gravity");
  p.node_damping = w.node_damping();
  p.tool_friction = w.tool_friction();
  p.time_step = w.time_step();
  if (w.has_plane()) {
    SupportPlane plane;
    plane.point = read_vec3(w.plane().point(), "plane.point");
    plane.normal = read_vec3(w.plane().normal(), "plane.normal");
    plane.static_friction = w.plane().static_friction();
    plane.dynamic_friction = w.plane().dynamic_friction();
    p.plane = plane;
  }
  if (w.remote_radii_size() != w.remote_users_size() ||
      w.presses_size() != w.remote_users_size() + 1)
    invalid("{} remote users, {} radii and {} presses (expected one more)", w.remote_users_size(),
            w.remote_radii_size(), w.presses_size());
  for (int i = 0; i < w.remote_users_size(); ++i) {
    ir.remote_users.push_back(to_int(w.remote_users(i), "remote user"));
    ir.remote_radii.push_back(w.remote_radii(i));
  }
  for (int i = 0; i < w.presses_size(); ++i)
    ir.presses.push_back({w.presses(i).pressing(),
                          read_vec3(w.presses(i).previous(), fmt::format("presses[{}]", i))});
  if (w.has_backing()) {
    const NodeBacking& b = w.backing();
    const auto backed = static_cast<std::uint64_t>(b.nodes_size());
    const auto count = static_cast<Eigen::Index>(backed);
    if (static_cast<std::uint64_t>(b.compliance_size()) != backed * backed ||
        static_cast<std::uint64_t>(b.offsets_size()) != backed ||
        static_cast<std::uint64_t>(b.damping_size()) != backed ||
        static_cast<std::uint64_t>(b.targets_size()) != 3 * backed ||
        static_cast<std::uint64_t>(b.normals_size()) != 3 * backed)
      invalid(
          "a backing of {} nodes with {} compliances, {} offsets, {} dampings, {} targets and {} "
          "normals (expected {}, "
          "{}, {}, {}, {})",
          backed, b.compliance_size(), b.offsets_size(), b.damping_size(), b.targets_size(),
          b.normals_size(), backed * backed, backed, backed, 3 * backed, 3 * backed);
    for (std::uint32_t node : b.nodes()) {
      if (node >= nodes) invalid("the backing names node {} of {}", node, nodes);
      ir.backing.nodes.push_back(static_cast<int>(node));
    }
    ir.backing.compliance.resize(count, count);
    read_values(b.compliance(), ir.backing.compliance, "backing.compliance");
    ir.backing.offsets.resize(count);
    read_values(b.offsets(), ir.backing.offsets, "backing.offsets");
    ir.backing.damping.resize(count);
    read_values(b.damping(), ir.backing.damping, "backing.damping");
    ir.backing.targets.resize(3 * count);
    read_values(b.targets(), ir.backing.targets, "backing.targets");
    ir.backing.normals.resize(3 * count);
    read_values(b.normals(), ir.backing.normals, "backing.normals");
  }
  return ir;
}

template <typename Indices>
std::vector<int> read_indices(const Indices& values, const char* what) {
  std::vector<int> out;
  out.reserve(static_cast<std::size_t>(values.size()));
  for (std::uint32_t value : values) out.push_back(to_int(value, what));
  return out;
}

// Sizes here; every index, sign and range by validate_home_spring_patch, before anything
// reads through an index.
cohaptic::HomeSpringPatch home_spring_from_wire(const HomeSpringPatch& w) {
  cohaptic::HomeSpringPatch patch;
  const auto vertices = static_cast<std::uint32_t>(w.surface_vertex_size());
  patch.rest_positions = read_xyz(w.rest_positions(), vertices, "rest_positions");
  patch.contact_vertex_count = to_int(w.contact_vertex_count(), "contact_vertex_count");
  if (w.triangles_size() % 3 != 0)
    invalid("{} triangle indices, not a multiple of 3", w.triangles_size());
  const std::vector<int> corners = read_indices(w.triangles(), "triangle corner");
  for (std::size_t i = 0; i < corners.size(); i += 3)
    patch.triangles.push_back({corners[i], corners[i + 1], corners[i + 2]});
  patch.ring_offsets = read_indices(w.ring_offsets(), "ring offset");
  patch.ring_vertices = read_indices(w.ring_vertices(), "ring vertex");
  patch.surface_vertex = read_indices(w.surface_vertex(), "surface vertex");
  patch.home_stiffness = w.home_stiffness();
  patch.neighbour_stiffness = w.neighbour_stiffness();
  patch.damping = w.damping();
  patch.trocar_pivot = read_vec3(w.trocar_pivot(), "trocar_pivot");
  if (w.has_grasp()) {
    patch.grasp.vertex = to_int(w.grasp().vertex(), "grasp vertex");
    patch.grasp.tool_at_grasp = read_vec3(w.grasp().tool_at_grasp(), "grasp.tool_at_grasp");
  }
  try {
    validate_home_spring_patch(patch);
  } catch (const cohaptic::Error& e) {
    invalid("{}", e.what());
  }
  return patch;
}

}  // namespace

CommonIr from_wire(const WireIr& w) {
  if (w.format_version() < CommonIr::kOldestReadableVersion ||
      w.format_version() > CommonIr::kFormatVersion)
    invalid("format version {}, expected {} to {}{}", w.format_version(),
            CommonIr::kOldestReadableVersion, CommonIr::kFormatVersion,
            w.format_version() == 1
                ? " (version 1 is read by cohaptic builds before the body framework)"
                : "");
  if (w.format_version() < 3 && w.has_fem() && w.fem().rows_generation() > 0)
    invalid("format version {} cannot carry compliance rows (version 3 can)", w.format_version());
  if (w.format_version() < 4 && w.has_fem() && w.fem().truncated_node_ids_size() > 0)
    invalid("format version {} cannot carry truncated held nodes (version 4 can)",
            w.format_version());
  if (w.format_version() < 6 && w.has_fem() && w.fem().contact_model() == CondensedFem::SPHERE)
    invalid(
        "format version {} carries a sphere body as M~, which this build no longer evaluates "
        "(version 6 carries its "
        "normal compliance)",
        w.format_version());
  CommonIr ir;
  ir.epoch = w.epoch();
  if (!std::isfinite(w.simulation_time()))
    invalid("simulation_time is not finite ({})", w.simulation_time());
  ir.simulation_time = w.simulation_time();
  ir.user = to_int(w.user(), "user");
  ir.object = to_int(w.object(), "object");
  if (!(std::isfinite(w.tool_radius()) && w.tool_radius() >= 0))
    invalid("tool_radius {} is not a finite length >= 0", w.tool_radius());
  ir.tool_radius = w.tool_radius();
  // +inf is a legitimate "no limit".
  if (!(w.force_limit() >= 0)) invalid("force_limit {} is not >= 0", w.force_limit());
  ir.force_limit = w.force_limit();
  switch (w.body_case()) {
    case WireIr::kFem:
      ir.body = fem_from_wire(w.fem());
      break;
    case WireIr::kMassSpring:
      ir.body = mass_spring_from_wire(w.mass_spring());
      break;
    case WireIr::kHomeSpring:
      ir.body = home_spring_from_wire(w.home_spring());
      break;
    case WireIr::kSeparation:
      try {
        ir.body = separation_from_wire(w.separation());
      } catch (const cohaptic::Error& e) {
        invalid("{}", e.what());
      }
      break;
    case WireIr::BODY_NOT_SET:
      invalid("no body of a kind this build knows");
  }
  return ir;
}

}  // namespace cohaptic::wire
