#include "common/ir/build_ir.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <unordered_map>

#include "common/condense/dof_blocks.h"
#include "common/contact/contact_patch.h"
#include "common/contact/find_contact.h"
#include "common/contact/sphere_contact.h"
#include "common/util/error.h"

namespace cohaptic {

std::vector<bool> kept_boundary_nodes(const DofMap& dofs, std::span<const int> boundary, const Eigen::MatrixXd& m_cb,
                                      double threshold) {
  std::vector<bool> kept(boundary.size(), true);
  if (threshold <= 0) return kept;
  Eigen::Index free_dofs = 0;
  for (int node : boundary)
    for (int axis = 0; axis < 3; ++axis) free_dofs += dofs.is_fixed(node, axis) ? 0 : 1;
  if (free_dofs != m_cb.cols())
    throw Error(fmt::format("kept_boundary_nodes: {} free boundary dofs for {} columns of M_CB", free_dofs, m_cb.cols()));
  std::vector<double> coupling(boundary.size(), 0.0);
  Eigen::Index column = 0;
  for (std::size_t b = 0; b < boundary.size(); ++b)
    for (int axis = 0; axis < 3; ++axis)
      if (!dofs.is_fixed(boundary[b], axis)) coupling[b] += m_cb.col(column++).squaredNorm();
  const double strongest = coupling.empty() ? 0 : *std::max_element(coupling.begin(), coupling.end());
  for (std::size_t b = 0; b < boundary.size(); ++b) kept[b] = coupling[b] >= threshold * threshold * strongest;
  return kept;
}

int nearest_touchable_triangle(const ElasticBody& body, const Eigen::Vector3d& position) {
  return nearest_triangle(body.mesh, body.surface, body.normals, body.touchable_triangles, position).triangle;
}

namespace {

// node_ids and fixed_axes of `nodes`, and the rest positions of the first row_node_count.
void fill_node_lists(const ElasticBody& body, std::span<const int> nodes, CondensedFemIr& fem) {
  for (int node : nodes) {
    fem.node_ids.push_back(body.mesh.node_tags[node]);
    fem.fixed_axes.push_back(body.dofs.fixed_axes[node]);
  }
  fem.rest_positions.resize(3, fem.row_node_count);
  for (int i = 0; i < fem.row_node_count; ++i) fem.rest_positions.col(i) = body.mesh.nodes.col(nodes[i]);
}

// The sphere model's part: the row nodes' normals, and W and q0 cut from the server's.
void fill_sphere_contact(const ElasticBody& body, std::span<const int> boundary, const SphereIrSource& source,
                         std::span<const int> nodes, IrPrecision precision, CondensedFemIr& fem) {
  if (!source.normal) throw Error("build_ir: the sphere contact model needs the server's normal compliance");
  const NormalCompliance& normal = *source.normal;
  fill_node_lists(body, nodes, fem);
  const auto n = static_cast<Eigen::Index>(nodes.size());
  SphereContactIr& sphere = fem.sphere.emplace();
  sphere.normals = Eigen::Matrix3Xd::Zero(3, n);
  sphere.free_clearance = Eigen::VectorXd::Zero(n);
  sphere.normal_compliance = Eigen::MatrixXd::Zero(n, n);
  sphere.obstacle_gaps = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  std::vector<int> slots(nodes.size(), -1);
  for (Eigen::Index i = 0; i < n; ++i) {
    const int node = nodes[static_cast<std::size_t>(i)];
    const bool obstacle_row = std::binary_search(source.obstacle_nodes.begin(), source.obstacle_nodes.end(), node);
    if (!obstacle_row && !holdable(body.contact_normals.col(node), body.dofs.fixed_axes[node])) continue;  // no candidate: zero
    const int slot = normal.slot_of(node);
    if (slot < 0) throw Error(fmt::format("build_ir: row node {} has no normal compliance", body.mesh.node_tags[node]));
    slots[static_cast<std::size_t>(i)] = slot;
    sphere.normals.col(i) = normal.normal(slot);
    sphere.free_clearance[i] = normal.free_clearance()[slot];
    if (obstacle_row) sphere.obstacle_gaps[i] = source.obstacles[static_cast<std::size_t>(node)].gap;
  }
  // W's entries between the rows' slots, each of W's columns read in ascending slot order
  // (W spans every candidate of the server's solve: far larger than the cache).
  std::vector<Eigen::Index> by_slot;
  for (Eigen::Index i = 0; i < n; ++i)
    if (slots[static_cast<std::size_t>(i)] >= 0) by_slot.push_back(i);
  std::sort(by_slot.begin(), by_slot.end(), [&](Eigen::Index a, Eigen::Index b) {
    return slots[static_cast<std::size_t>(a)] < slots[static_cast<std::size_t>(b)];
  });
  for (const Eigen::Index j : by_slot) {
    const double* column = normal.w().col(slots[static_cast<std::size_t>(j)]).data();
    for (const Eigen::Index i : by_slot) sphere.normal_compliance(i, j) = column[slots[static_cast<std::size_t>(i)]];
  }
  if (precision == IrPrecision::f32) sphere.normal_compliance = sphere.normal_compliance.cast<float>().cast<double>();
  std::vector<char> pushes(static_cast<std::size_t>(normal.capacity()), 0);
  for (int slot : source.contact_slots) pushes[static_cast<std::size_t>(slot)] = 1;
  for (Eigen::Index i = 0; i < n; ++i)
    if (slots[static_cast<std::size_t>(i)] >= 0 && pushes[static_cast<std::size_t>(slots[static_cast<std::size_t>(i)])])
      sphere.contacts.push_back(static_cast<int>(i));
  for (int node : boundary) sphere.held_node_ids.push_back(body.mesh.node_tags[node]);
}

}  // namespace

IntermediateRepresentation build_ir(const ElasticBody& body, IncrementalCondensation& condensation,
                                    std::span<const UserTool> users, std::size_t user_index,
                                    std::span<const Eigen::Vector3d> boundary_displacement,
                                    const IrBuildOptions& options, std::uint64_t epoch, double simulation_time,
                                    const RestDisplacement& rest, const SphereIrSource& sphere_source) {
  const UserTool& own = users[user_index];
  const std::vector<int>& boundary = condensation.boundary_nodes();
  if (boundary_displacement.size() != boundary.size())
    throw Error(fmt::format("build_ir: {} boundary displacements for {} boundary nodes", boundary_displacement.size(),
                            boundary.size()));
  if (own.nearest_triangle < 0 || own.nearest_triangle >= body.surface.triangle_count())
    throw Error(fmt::format("build_ir: user {} has no nearest triangle", own.user));

  std::vector<bool> held(static_cast<std::size_t>(body.mesh.node_count()), false);
  for (int node : boundary) held[node] = true;
  const auto holds_node = [&](int triangle) {
    const Triangle& tri = body.surface.triangles[triangle];
    return held[tri[0]] || held[tri[1]] || held[tri[2]];
  };
  if (holds_node(own.nearest_triangle))
    throw Error(fmt::format("build_ir: user {}'s contact triangle has a node held as a boundary node", own.user));

  std::vector<bool> allowed(body.surface.triangles.size(), false);
  for (int t : body.touchable_triangles) allowed[t] = !holds_node(t);
  // The sphere model's patch covers every node the sphere holds (sphere_contact.h).
  const bool sphere = options.contact_model == ContactModel::sphere;
  const auto patch_of = [&](const UserTool& user) {
    return sphere ? sphere_patch(body.mesh, body.surface, body.surface_tree, user.nearest_triangle, {user.position, user.radius},
                                 options.patch_rings, allowed, user.carried_nodes)
                  : contact_patch(body.surface, user.nearest_triangle, options.patch_rings, allowed);
  };
  const std::vector<int> patch = patch_of(own);

  IntermediateRepresentation ir;
  ir.epoch = epoch;
  ir.simulation_time = simulation_time;
  ir.user = own.user;
  ir.tool_radius = own.radius;
  ir.force_limit = options.force_limit;
  CondensedFemIr& fem = std::get<CondensedFemIr>(ir.body);
  fem.contact_model = options.contact_model;
  fem.precision = options.precision;

  // Local numbering: patch nodes, remote contact nodes not in the patch, then B.
  std::vector<int> nodes;
  std::unordered_map<int, int> local;
  const auto add_node = [&](int node) {
    const auto [it, inserted] = local.emplace(node, static_cast<int>(nodes.size()));
    if (inserted) nodes.push_back(node);
    return it->second;
  };
  std::unordered_map<int, int> patch_index;
  for (int t : patch) {
    patch_index.emplace(t, static_cast<int>(fem.patch.size()));
    IrTriangle tri;
    tri.surface_index = t;
    for (int k = 0; k < 3; ++k) tri.nodes[k] = add_node(body.surface.triangles[t][k]);
    tri.normal = body.normals.face[t];
    fem.patch.push_back(tri);
  }
  std::vector<bool> in_guard(body.surface.triangles.size(), false);
  for (std::size_t i = 0; i < patch.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const auto it = patch_index.find(body.surface.triangle_neighbours[patch[i]][k]);
      fem.patch[i].neighbours[k] = it == patch_index.end() ? -1 : it->second;
      fem.patch[i].edge_normals[k] = edge_pseudo_normal(body.surface, body.normals, patch[i], k);
    }
  fem.patch_node_count = static_cast<int>(nodes.size());
  fem.patch_vertex_normals.resize(3, fem.patch_node_count);
  for (int i = 0; i < fem.patch_node_count; ++i) fem.patch_vertex_normals.col(i) = body.normals.vertex.col(nodes[i]);
  // The guard ring: every surface triangle sharing a vertex with the patch, not in it.
  for (int i = 0; i < fem.patch_node_count; ++i)
    for (int t : body.surface.node_triangles(nodes[i]))
      if (!patch_index.count(t) && !in_guard[t]) {
        in_guard[t] = true;
        IrGuardTriangle guard;
        for (int k = 0; k < 3; ++k) guard.corners[k] = body.mesh.nodes.col(body.surface.triangles[t][k]);
        guard.normal = body.normals.face[t];
        fem.guard.push_back(guard);
      }
  for (std::size_t j = 0; j < users.size(); ++j) {
    if (j == user_index || users[j].nearest_triangle < 0 || holds_node(users[j].nearest_triangle)) continue;
    IrRemoteContact remote;
    remote.user = users[j].user;
    for (int k = 0; k < 3; ++k) remote.nodes[k] = add_node(body.surface.triangles[users[j].nearest_triangle][k]);
    if (sphere)  // the remote sphere's candidates are contact nodes too
      for (int node : triangle_nodes(body.surface, patch_of(users[j]))) add_node(node);
    const int t = users[j].nearest_triangle;
    remote.normal = body.normals.face[t];
    for (int k = 0; k < 3; ++k) {
      remote.edge_normals[k] = edge_pseudo_normal(body.surface, body.normals, t, k);
      remote.vertex_normals[k] = body.normals.vertex.col(body.surface.triangles[t][k]);
    }
    remote.tool_radius = users[j].radius;
    fem.remotes.push_back(remote);
  }
  if (sphere)  // the nodes the server's state holds against an obstacle
    for (int node : sphere_source.obstacle_nodes) add_node(node);
  fem.row_node_count = static_cast<int>(nodes.size());
  if (sphere) {
    fill_sphere_contact(body, boundary, sphere_source, nodes, options.precision, fem);
    return ir;
  }
  const std::vector<int> contact_nodes = nodes;
  const CondensedOperator op = condensation.condense(contact_nodes);

  // The held nodes the IR carries, with their columns of M_CB: all of them, or with B
  // truncation only those whose coupling to the contact rows is not negligible (the others
  // are listed apart, for a client that condenses itself).
  std::vector<Eigen::Index> kept_columns;
  std::vector<double> kept_displacement;
  const std::vector<bool> kept = kept_boundary_nodes(body.dofs, boundary, op.m_cb, options.boundary_truncation);
  Eigen::Index column = 0;
  for (std::size_t b = 0; b < boundary.size(); ++b) {
    if (kept[b]) add_node(boundary[b]);
    for (int axis = 0; axis < 3; ++axis) {
      if (body.dofs.is_fixed(boundary[b], axis)) continue;
      if (kept[b]) {
        kept_columns.push_back(column);
        kept_displacement.push_back(boundary_displacement[b][axis]);
      }
      ++column;
    }
    if (!kept[b]) {
      fem.truncated_node_ids.push_back(body.mesh.node_tags[boundary[b]]);
      fem.truncated_fixed_axes.push_back(body.dofs.fixed_axes[boundary[b]]);
    }
  }

  fill_node_lists(body, nodes, fem);

  const auto kept_count = static_cast<Eigen::Index>(kept_columns.size());
  fem.m_tilde.resize(op.m_cc.rows(), op.m_cc.cols() + kept_count);
  fem.m_tilde.leftCols(op.m_cc.cols()) = op.m_cc;
  for (Eigen::Index k = 0; k < kept_count; ++k) fem.m_tilde.col(op.m_cc.cols() + k) = op.m_cb.col(kept_columns[k]);
  fem.boundary_displacement = Eigen::Map<const Eigen::VectorXd>(kept_displacement.data(), kept_count);
  if (rest) {  // f = M~ (u - u0) over C and all of B
    std::vector<int> dofs = free_dofs_of_nodes(body.dofs, contact_nodes);
    const std::vector<int> held_dofs = free_dofs_of_nodes(body.dofs, boundary);
    dofs.insert(dofs.end(), held_dofs.begin(), held_dofs.end());
    const Eigen::VectorXd u0 = rest(dofs);
    fem.rest_forces = -(op.m_cc * u0.head(op.m_cc.cols()) + op.m_cb * u0.tail(op.m_cb.cols()));
  }
  if (options.precision == IrPrecision::f32) {
    fem.m_tilde = fem.m_tilde.cast<float>().cast<double>();
    fem.boundary_displacement = fem.boundary_displacement.cast<float>().cast<double>();
  }
  return ir;
}

}  // namespace cohaptic
