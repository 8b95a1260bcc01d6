// The sphere contact model's part of Simulation's step (simulation.h).
#include "common/sim/simulation.h"

#include <algorithm>

#include "common/contact/obstacle_constraints.h"

namespace cohaptic {

Simulation::SphereContacts::SphereContacts(const ElasticBody& body, ComplianceColumns& columns,
                                           std::span<const ObstacleDistance> obstacles,
                                           std::size_t users)
    : solve_(body, columns,
             obstacles.empty()
                 ? std::vector<SphereConstraint>{}
                 : obstacle_constraints(body.mesh, body.surface, body.dofs, obstacles)),
      node_of_tag_(node_indices_by_tag(body.mesh)),
      users_(users) {}

void Simulation::SphereContacts::mark(Simulation& s, int user_slot) {
  const ElasticBody& body = s.body_;
  UserState& user = s.users_[static_cast<std::size_t>(user_slot)];
  User& mine = users_[static_cast<std::size_t>(user_slot)];
  const SphereTool sphere{user.position, user.radius};
  const int rings = s.options_.ir.patch_rings;
  mine.patch_nodes = triangle_nodes(
      body.surface, sphere_patch(body.mesh, body.surface, body.surface_tree, user.nearest, sphere,
                                 rings, s.touchable_triangle_));
  // Carried nodes the patch now holds anyway are no longer carried.
  std::erase_if(mine.carried, [&](int node) {
    return std::find(mine.patch_nodes.begin(), mine.patch_nodes.end(), node) !=
           mine.patch_nodes.end();
  });
  const std::vector<int> nodes =
      mine.carried.empty()
          ? mine.patch_nodes
          : triangle_nodes(body.surface,
                           sphere_patch(body.mesh, body.surface, body.surface_tree, user.nearest,
                                        sphere, rings, s.touchable_triangle_, mine.carried));
  for (int node : nodes) s.under_tool_[node] = s.in_patch_[node] = true;
  mine.nodes = nodes;
  mine.holds = nodes_held_by_spheres(body.mesh, body.dofs, body.contact_normals, nodes,
                                     std::span(&sphere, 1))
                   .nodes;
  user.pressing = !mine.holds.empty() || !mine.carried.empty();
}

bool Simulation::SphereContacts::settle(Simulation& s, HeldSetUpdate& update) {
  constexpr int kMaxCarryPasses = 4;  // each pass only adds nodes; in practice one settles it
  const ElasticBody& body = s.body_;
  std::vector<int> user_of_sphere;  // spheres() lists the known users in order
  for (std::size_t u = 0; u < s.users_.size(); ++u)
    if (s.users_[u].known) user_of_sphere.push_back(static_cast<int>(u));
  const std::vector<SphereTool> tools = s.spheres();
  bool boundary_changed = false;
  for (int pass = 0;; ++pass) {
    const StateSolution state = solve(s);
    // The pushed nodes of this state, each with the user whose sphere pushes it, that no
    // patch holds (a node in another user's patch is a contact node of this user's IR too).
    std::vector<int> pushed;
    std::vector<std::pair<int, int>> left_out;
    const std::span<const int> obstacle_rows = solve_.obstacle_rows();
    for (std::size_t i = 0; i < state.contact_dofs.size(); ++i) {
      const int node = state.contact_dofs[i] / 3;
      if (state.contact_forces[static_cast<Eigen::Index>(i)] == 0.0 ||
          (!pushed.empty() && pushed.back() == node))
        continue;  // not pushed, or its other axes
      pushed.push_back(node);
      if (s.in_patch_[node] || std::binary_search(obstacle_rows.begin(), obstacle_rows.end(), node))
        continue;
      const SphereConstraint constraint =
          sphere_constraint(body.mesh.nodes.col(node), body.contact_normals.col(node),
                            body.dofs.fixed_axes[node], tools)
              .value();
      left_out.emplace_back(node, user_of_sphere[static_cast<std::size_t>(constraint.tool)]);
    }
    if (left_out.empty()) {
      // A carried node the state no longer pushes leaves its patch from the next step on.
      for (User& user : users_)
        std::erase_if(user.carried, [&](int node) {
          return std::find(pushed.begin(), pushed.end(), node) == pushed.end();
        });
      return boundary_changed;
    }
    if (pass == kMaxCarryPasses) {
      update.nodes_outside_patches = static_cast<int>(left_out.size());
      return boundary_changed;
    }
    for (const auto& [node, user] : left_out)
      users_[static_cast<std::size_t>(user)].carried.push_back(node);
    for (const auto& [node, user] : left_out) mark(s, user);
    boundary_changed |= s.update_boundary();
  }
}

StateSolution Simulation::SphereContacts::solve(Simulation& s,
                                                std::span<const SphereTool> spheres) {
  std::vector<int> candidates;
  for (std::size_t u = 0; u < s.users_.size(); ++u)
    if (s.users_[u].known)
      candidates.insert(candidates.end(), users_[u].nodes.begin(), users_[u].nodes.end());
  return solve_.solve(s.condensation_, candidates, spheres, s.boundary_dof_displacement());
}

bool Simulation::SphereContacts::follows_nearest(int user) const {
  const User& mine = users_[static_cast<std::size_t>(user)];
  return mine.holds.empty() && mine.carried.empty();
}

bool Simulation::SphereContacts::irs_stand(const Simulation& s) const {
  if (built_rows_.empty()) return false;
  // A node must be a row of the IRs, pushed along the direction its slot had then: only
  // where it is held or pushed does the direction matter (elsewhere it pushes nothing).
  const NormalCompliance& normal = solve_.normal_compliance();
  const auto stands = [&](int node) {
    if (!built_rows_[static_cast<std::size_t>(node)]) return false;
    const int slot = normal.slot_of(node);
    const auto built =
        std::lower_bound(built_row_directions_.begin(), built_row_directions_.end(), node,
                         [](const auto& entry, int n) { return entry.first < n; });
    return slot < 0 || built == built_row_directions_.end() || built->first != node ||
           normal.normal(slot) == built->second;
  };
  for (std::size_t u = 0; u < s.users_.size(); ++u) {
    if (!s.users_[u].known) continue;
    for (const std::vector<int>* nodes : {&users_[u].holds, &users_[u].carried})
      if (!std::ranges::all_of(*nodes, stands)) return false;
  }
  return std::ranges::all_of(solve_.obstacle_contacts(), stands);
}

SphereIrSource Simulation::SphereContacts::ir_source(const Simulation& s, bool sets_changed) {
  if (sets_changed) built_rows_.assign(static_cast<std::size_t>(s.body_.mesh.node_count()), 0);
  return {&solve_.normal_compliance(), solve_.contact_slots(), solve_.obstacle_rows(),
          solve_.obstacle_constraints()};
}

void Simulation::SphereContacts::built(const Simulation& /*s*/, const PreparedIR& ir) {
  for (const std::int64_t tag : condensed_fem(ir.ir).node_ids)
    built_rows_[static_cast<std::size_t>(node_of_tag_.at(tag))] = 1;
}

void Simulation::SphereContacts::built_all(const Simulation& s) {
  built_row_directions_.clear();
  const NormalCompliance& normal = solve_.normal_compliance();
  for (int node = 0; node < s.body_.mesh.node_count(); ++node)
    if (const int slot = built_rows_[static_cast<std::size_t>(node)] ? normal.slot_of(node) : -1;
        slot >= 0)
      built_row_directions_.emplace_back(node, normal.normal(slot));
}

const std::vector<NodeDistance>& Simulation::SphereContacts::near_obstacles() const {
  // Its state solve holds the obstacles' nodes, so none is ever near: one empty list, const,
  // shared by every simulation.
  static const std::vector<NodeDistance> none;
  return none;
}

}  // namespace cohaptic
