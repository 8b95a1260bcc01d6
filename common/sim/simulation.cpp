#include "common/sim/simulation.h"

#include <fmt/format.h>

#include <algorithm>
#include <future>
#include <limits>
#include <utility>

#include "common/contact/contact_patch.h"
#include "common/contact/find_contact.h"
#include "common/contact/nearest_surface_nodes.h"
#include "common/contact/obstacle_constraints.h"
#include "common/sim/sphere_state_solve.h"
#include "common/util/error.h"
#include "common/util/stopwatch.h"

namespace cohaptic {
namespace {

// In the nearest triangles an IR was built for: a sphere that held nodes then.
constexpr int kHoldingSphere = -2;

}  // namespace

Simulation::Simulation(const ElasticBody& body, std::span<const Obstacle> obstacles,
                       ComplianceColumns& columns, const std::vector<ToolSpec>& tools,
                       SimulationOptions options)
    : body_(body),
      columns_(columns),
      options_(options),
      condensation_(columns, body.dofs,
                    [&] {
                      IncrementalCondensation::Options condensation;
                      condensation.naive = options.naive_every_step;
                      return condensation;
                    }()),
      candidates_(body.mesh, body.surface, body.touchable_triangles),
      touchable_triangle_(body.surface.triangles.size(), false) {
  for (int t : body.touchable_triangles) touchable_triangle_[t] = true;
  users_.resize(tools.size());
  for (std::size_t u = 0; u < users_.size(); ++u) users_[u].radius = tools[u].radius;
  p0_states_.resize(users_.size());
  if (!obstacles.empty()) {
    const Eigen::Matrix3Xd surface_points = surface_rest_points(body.mesh, body.surface);
    for (const Obstacle& obstacle : obstacles) obstacles_.emplace_back(obstacle, surface_points);
    if (!sphere_model()) clearance_ = ObstacleClearance(obstacles_, surface_points);
  }
  if (sphere_model()) {
    sphere_solve_.emplace(
        body, columns,
        obstacles_.empty() ? std::vector<SphereConstraint>{}
                           : obstacle_constraints(body.mesh, body.surface, body.dofs, obstacles_));
    node_of_tag_ = node_indices_by_tag(body.mesh);
  }
}

void Simulation::set_tool(int user, const Eigen::Vector3d& position) {
  users_[user].known = position.allFinite();
  users_[user].position = position;
}

void Simulation::clear_tool(int user) { users_[user].known = false; }

void Simulation::continue_epochs(int user, std::uint64_t epoch) {
  users_[user].epoch = std::max(users_[user].epoch, epoch);
}

void Simulation::hold(int node, const HeldNode& held) {
  condensation_.add_boundary_node(node);
  held_[node] = held;
  boundary_dirty_ = true;
}

void Simulation::release(int node) {
  condensation_.remove_boundary_node(node);
  held_.erase(node);
  boundary_dirty_ = true;
}

std::vector<Eigen::Vector3d> Simulation::boundary_displacement() const {
  return boundary_displacement(condensation_);
}

std::vector<Eigen::Vector3d> Simulation::boundary_displacement(
    const IncrementalCondensation& condensation) const {
  std::vector<Eigen::Vector3d> out;
  for (int node : condensation.boundary_nodes()) out.push_back(held_.at(node).displacement);
  return out;
}

void Simulation::set_support(std::unique_ptr<SupportedCompliance> support) {
  supported_.reset();
  if (support) {
    IncrementalCondensation::Options options;
    options.naive = options_.naive_every_step;
    supported_.emplace(std::move(support), body_.dofs, options);
  }
  support_changed_ = true;
}

IncrementalCondensation& Simulation::ir_condensation() {
  if (!supported_) return condensation_;
  supported_->condensation().set_boundary_nodes(condensation_.boundary_nodes());
  return supported_->condensation();
}

Eigen::VectorXd Simulation::boundary_dof_displacement() const {
  std::vector<double> values;
  for (int node : condensation_.boundary_nodes())
    for (int axis = 0; axis < 3; ++axis)
      if (!body_.dofs.is_fixed(node, axis)) values.push_back(held_.at(node).displacement[axis]);
  return Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

// A node follows one tool: a user whose triangle shares a node with an earlier pressing
// user's is left out of the state, as a client leaves out a remote tool whose triangle
// overlaps its own (kRemoteOverlap). Listed twice, the node would make the condensed
// compliance singular, and every step would fail while the two tools stay together.
std::vector<PressingContact> Simulation::pressing_contacts() const {
  std::vector<PressingContact> contacts;
  for (const UserState& user : users_)
    if (user.pressing && user.contact) {
      const Triangle& tri = body_.surface.triangles[user.contact->triangle];
      if (std::any_of(contacts.begin(), contacts.end(),
                      [&](const PressingContact& taken) { return share_a_node(taken.nodes, tri); }))
        continue;
      contacts.push_back(
          {{tri[0], tri[1], tri[2]}, user.contact->weights, user.contact->displacement});
    }
  return contacts;
}

StateSolution Simulation::solve(std::span<const PressingContact> contacts) {
  return solve_state(columns_, condensation_, body_.dofs, contacts, boundary_dof_displacement(),
                     options_.ir.contact_model, applied_);
}

StateSolution Simulation::solve() {
  return sphere_model() ? solve_spheres(spheres()) : solve(pressing_contacts());
}

StateSolution Simulation::solve_unloaded() {
  if (sphere_model()) return solve_spheres(spheres());  // in no FEM pair (refused), so never loaded
  return solve_state(columns_, condensation_, body_.dofs, pressing_contacts(),
                     boundary_dof_displacement(), options_.ir.contact_model);
}

std::vector<SphereTool> Simulation::spheres() const {
  std::vector<SphereTool> out;
  for (const UserState& user : users_)
    if (user.known) out.push_back({user.position, user.radius});
  return out;
}

StateSolution Simulation::solve_spheres(std::span<const SphereTool> spheres) {
  std::vector<int> candidates;
  for (const UserState& user : users_)
    if (user.known)
      candidates.insert(candidates.end(), user.sphere_nodes.begin(), user.sphere_nodes.end());
  return sphere_solve_->solve(condensation_, candidates, spheres, boundary_dof_displacement());
}

bool Simulation::sphere_irs_stand() const {
  if (built_sphere_rows_.empty()) return false;
  // A node must be a row of the IRs, pushed along the direction its slot had then: only
  // where it is held or pushed does the direction matter (elsewhere it pushes nothing).
  const NormalCompliance& normal = sphere_solve_->normal_compliance();
  const auto stands = [&](int node) {
    if (!built_sphere_rows_[static_cast<std::size_t>(node)]) return false;
    const int slot = normal.slot_of(node);
    const auto built =
        std::lower_bound(built_row_directions_.begin(), built_row_directions_.end(), node,
                         [](const auto& entry, int n) { return entry.first < n; });
    return slot < 0 || built == built_row_directions_.end() || built->first != node ||
           normal.normal(slot) == built->second;
  };
  for (const UserState& user : users_) {
    if (!user.known) continue;
    for (const std::vector<int>* nodes : {&user.sphere_holds, &user.sphere_carried})
      if (!std::ranges::all_of(*nodes, stands)) return false;
  }
  return std::ranges::all_of(sphere_solve_->obstacle_contacts(), stands);
}

void Simulation::mark_sphere(UserState& user, std::vector<bool>& under_tool,
                             std::vector<bool>& in_patch,
                             const std::vector<bool>& touchable) const {
  const SphereTool sphere{user.position, user.radius};
  const int rings = options_.ir.patch_rings;
  user.sphere_patch_nodes =
      triangle_nodes(body_.surface, sphere_patch(body_.mesh, body_.surface, body_.surface_tree,
                                                 user.nearest, sphere, rings, touchable));
  // Carried nodes the patch now holds anyway are no longer carried.
  std::erase_if(user.sphere_carried, [&](int node) {
    return std::find(user.sphere_patch_nodes.begin(), user.sphere_patch_nodes.end(), node) !=
           user.sphere_patch_nodes.end();
  });
  const std::vector<int> nodes =
      user.sphere_carried.empty()
          ? user.sphere_patch_nodes
          : triangle_nodes(body_.surface,
                           sphere_patch(body_.mesh, body_.surface, body_.surface_tree, user.nearest,
                                        sphere, rings, touchable, user.sphere_carried));
  for (int node : nodes) under_tool[node] = in_patch[node] = true;
  user.sphere_nodes = nodes;
  user.sphere_holds = nodes_held_by_spheres(body_.mesh, body_.dofs, body_.contact_normals, nodes,
                                            std::span(&sphere, 1))
                          .nodes;
  user.pressing = !user.sphere_holds.empty() || !user.sphere_carried.empty();
}

bool Simulation::carry_pushed_nodes_into_patches(std::vector<bool>& under_tool,
                                                 std::vector<bool>& in_patch,
                                                 HeldSetUpdate& update) {
  constexpr int kMaxCarryPasses = 4;  // each pass only adds nodes; in practice one settles it
  std::vector<int> user_of_sphere;    // spheres() lists the known users in order
  for (std::size_t u = 0; u < users_.size(); ++u)
    if (users_[u].known) user_of_sphere.push_back(static_cast<int>(u));
  const std::vector<SphereTool> tools = spheres();
  bool boundary_changed = false;
  for (int pass = 0;; ++pass) {
    const StateSolution state = solve();
    // The pushed nodes of this state, each with the user whose sphere pushes it, that no
    // patch holds (a node in another user's patch is a contact node of this user's IR too).
    std::vector<int> pushed;
    std::vector<std::pair<int, int>> left_out;
    const std::span<const int> obstacle_rows = sphere_solve_->obstacle_rows();
    for (std::size_t i = 0; i < state.contact_dofs.size(); ++i) {
      const int node = state.contact_dofs[i] / 3;
      if (state.contact_forces[static_cast<Eigen::Index>(i)] == 0.0 ||
          (!pushed.empty() && pushed.back() == node))
        continue;  // not pushed, or its other axes
      pushed.push_back(node);
      if (in_patch[node] || std::binary_search(obstacle_rows.begin(), obstacle_rows.end(), node))
        continue;
      const SphereConstraint constraint =
          sphere_constraint(body_.mesh.nodes.col(node), body_.contact_normals.col(node),
                            body_.dofs.fixed_axes[node], tools)
              .value();
      left_out.emplace_back(node, user_of_sphere[static_cast<std::size_t>(constraint.tool)]);
    }
    if (left_out.empty()) {
      // A carried node the state no longer pushes leaves its patch from the next step on.
      for (UserState& user : users_)
        std::erase_if(user.sphere_carried, [&](int node) {
          return std::find(pushed.begin(), pushed.end(), node) == pushed.end();
        });
      return boundary_changed;
    }
    if (pass == kMaxCarryPasses) {
      update.nodes_outside_patches = static_cast<int>(left_out.size());
      return boundary_changed;
    }
    for (const auto& [node, user] : left_out)
      users_[static_cast<std::size_t>(user)].sphere_carried.push_back(node);
    for (const auto& [node, user] : left_out)
      mark_sphere(users_[static_cast<std::size_t>(user)], under_tool, in_patch,
                  touchable_triangle_);
    boundary_changed |= update_boundary(under_tool, in_patch);
  }
}

Eigen::Matrix3Xd Simulation::displacement_of(std::span<const int> nodes) {
  return displacement_of_nodes(columns_, solve(), nodes);
}

bool Simulation::update_obstacle_contacts(const std::vector<bool>& under_tool) {
  const StateSolution state = solve();
  // Held nodes whose obstacle would have to pull (holding force into the obstacle) go free.
  std::vector<int> pulling;
  for (std::size_t b = 0, dof = 0; b < condensation_.boundary_nodes().size(); ++b) {
    const int node = condensation_.boundary_nodes()[b];
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    for (int axis = 0; axis < 3; ++axis)
      if (!body_.dofs.is_fixed(node, axis))
        force[axis] = state.boundary_forces[static_cast<Eigen::Index>(dof++)];
    const HeldNode& held = held_.at(node);
    if (held.obstacle < 0) continue;
    const Eigen::Vector3d at = body_.mesh.nodes.col(node) + held.displacement;
    if (force.dot(obstacles_[held.obstacle].closest_point(at).normal) < 0) pulling.push_back(node);
  }
  // Free nodes whose displaced position penetrates an obstacle are held on it. Only nodes
  // that may have reached one since their last query are queried (ObstacleClearance).
  const Eigen::Matrix3Xd u = displacement_of_nodes(columns_, state, body_.surface.nodes);
  near_obstacles_.clear();  // as of this pass's state
  std::vector<std::pair<int, HeldNode>> penetrating;
  for (std::size_t i = 0; i < body_.surface.nodes.size(); ++i) {
    const int node = body_.surface.nodes[i];
    if (held_.count(node) || under_tool[node] || body_.dofs.fixed_axes[node] == kAllAxes) continue;
    const Eigen::Vector3d rest = body_.mesh.nodes.col(node);
    const Eigen::Vector3d moved = rest + u.col(static_cast<Eigen::Index>(i));
    if (const double estimate = clearance_.estimate(i, moved);
        estimate < options_.near_obstacle_distance && !columns_.has_column(node))
      near_obstacles_.push_back({node, estimate});
    if (clearance_.certainly_clear(i, moved)) continue;
    ObstaclePoint nearest{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                          std::numeric_limits<double>::infinity(), -1};
    for (int o = 0; o < static_cast<int>(obstacles_.size()); ++o) {
      const ObstaclePoint hit = obstacles_[o].closest_point(moved);
      if (hit.signed_distance < nearest.signed_distance) nearest = hit;
      if (hit.signed_distance >= 0) continue;
      penetrating.push_back({node, {hit.point - rest, o}});
      break;
    }
    clearance_.record(i, moved, nearest.signed_distance, nearest.normal);
  }
  for (int node : pulling) release(node);
  std::vector<int> joining;
  for (const auto& entry : penetrating) joining.push_back(entry.first);
  columns_.compute_columns(joining);  // one multi-right-hand-side solve for all that join
  for (const auto& [node, held] : penetrating) hold(node, held);
  return !pulling.empty() || !penetrating.empty();
}

void Simulation::set_step_delay_nodes(int nodes) {
  if (nodes < 0) throw Error(fmt::format("set_step_delay_nodes: {} nodes", nodes));
  if (nodes == options_.step_delay_nodes) return;
  options_.step_delay_nodes = nodes;
  step_delay_changed_ = true;
}

void Simulation::release_step_delay_nodes() {
  std::vector<int> step_nodes;
  for (const auto& [node, held] : held_)
    if (held.obstacle < 0) step_nodes.push_back(node);
  for (int node : step_nodes) release(node);
}

bool Simulation::update_boundary(const std::vector<bool>& under_tool,
                                 const std::vector<bool>& in_patch) {
  boundary_dirty_ = false;
  const std::vector<int> current = condensation_.boundary_nodes();
  for (int node : current)
    if (under_tool[node]) release(node);  // the tool's triangle wins

  // Step delay: hold the N nodes nearest the pressing tools while any presses; a new N
  // (set_step_delay_nodes) chooses them afresh.
  if (std::exchange(step_delay_changed_, false)) release_step_delay_nodes();
  std::vector<Eigen::Vector3d> contact_points;
  for (const UserState& user : users_)
    if (user.pressing) contact_points.push_back(user.position);
  bool step_delay_held = false;
  for (const auto& [node, held] : held_) step_delay_held |= held.obstacle < 0;
  if (options_.step_delay_nodes > 0 && !contact_points.empty() && !step_delay_held) {
    // Chosen outside every user's patch, so that the patches keep their triangles.
    const std::vector<int> nodes = nearest_surface_nodes(
        body_.mesh, body_.surface, body_.dofs, contact_points, options_.step_delay_nodes, in_patch);
    std::vector<int> fresh;
    for (int node : nodes)
      if (!held_.count(node)) fresh.push_back(node);
    // Held where they were before the touch: the previous step's state.
    const Eigen::Matrix3Xd u = displacement_of_nodes(
        columns_, sphere_model() ? solve_spheres(previous_spheres_) : solve(previous_contacts_),
        fresh);
    for (std::size_t i = 0; i < fresh.size(); ++i)
      hold(fresh[i], {u.col(static_cast<Eigen::Index>(i)), -1});
  } else if (contact_points.empty() && step_delay_held) {
    release_step_delay_nodes();
  }

  // Under the sphere contact model the state solve holds the obstacles' nodes itself.
  for (int pass = 0; pass < options_.obstacle_iterations && !obstacles_.empty() && !sphere_model();
       ++pass)
    if (!update_obstacle_contacts(under_tool)) break;
  return boundary_dirty_;
}

StepReport Simulation::step(double time) {
  update_held_set();
  return build_irs(time);
}

void Simulation::find_contacts() {
  // The step's scratch lives in the simulation, so that a step allocates no more than its
  // mathematics does.
  std::vector<bool>& under_tool = under_tool_;
  std::vector<bool>& in_patch = in_patch_;
  under_tool.assign(static_cast<std::size_t>(body_.mesh.node_count()), false);
  in_patch.assign(under_tool.size(), false);
  for (std::size_t u = 0; u < users_.size(); ++u) {
    UserState& user = users_[u];
    if (!user.known) {
      user.pressing = false;
      user.sphere_carried.clear();
      user.contact.reset();
      user.ir.reset();
      continue;
    }
    candidates_.find(user.position, surface_candidates_, touchable_candidates_);
    user.contact = find_contact(body_.mesh, body_.surface, body_.normals, touchable_candidates_,
                                user.position, user.radius, surface_candidates_)
                       .contact;
    user.pressing = user.contact.has_value();
    // A contact's triangle is the nearest touchable one, found by the same rule.
    user.nearest = user.pressing ? user.contact->triangle
                                 : nearest_triangle(body_.mesh, body_.surface, body_.normals,
                                                    touchable_candidates_, user.position)
                                       .triangle;
    for (int node : body_.surface.triangles[user.nearest]) under_tool[node] = true;
    if (options_.step_delay_nodes > 0)  // only step-delay nodes are chosen outside the patches
      for (int t :
           contact_patch(body_.surface, user.nearest, options_.ir.patch_rings, touchable_triangle_))
        for (int node : body_.surface.triangles[t]) in_patch[node] = true;
    if (sphere_model()) mark_sphere(user, under_tool, in_patch, touchable_triangle_);
  }
}

void Simulation::update_held_set() {
  find_contacts();
  Stopwatch watch;
  HeldSetUpdate update;
  update.changed = update_boundary(under_tool_, in_patch_);
  if (sphere_model())
    update.changed |= carry_pushed_nodes_into_patches(under_tool_, in_patch_, update);
  update.elapsed_ms = watch.elapsed_ms();
  held_set_update_ = update;
}

StepReport Simulation::build_irs(double time) {
  if (!held_set_update_)
    throw Error("Simulation::build_irs: the held set was not updated since the IRs were built");
  const HeldSetUpdate update = *std::exchange(held_set_update_, std::nullopt);
  StepReport report;
  report.sphere_nodes_outside_patches = update.nodes_outside_patches;
  Stopwatch watch;
  std::vector<UserTool>& tools = step_tools_;
  tools.clear();
  std::vector<int>& nearest = step_nearest_;
  nearest.clear();
  for (std::size_t u = 0; u < users_.size(); ++u) {
    const UserState& user = users_[u];
    // A sphere that holds nothing follows its nearest triangle, so that its IR is there when
    // it touches; once it holds nodes, their being row nodes is what counts (below).
    const bool follows_nearest =
        !sphere_model() || (user.sphere_holds.empty() && user.sphere_carried.empty());
    nearest.push_back(!user.known ? -1 : follows_nearest ? user.nearest : kHoldingSphere);
    if (user.known)
      tools.push_back(
          {static_cast<int>(u), user.position, user.radius, user.nearest, user.sphere_carried});
  }
  // Under naive_every_step M~ is computed again every step, as the paper's conventional loop
  // did (that cost is the step delay), but with unchanged sets it is the same IR: a new one
  // (a new epoch) is published only when a set changed.
  const bool support_changed = std::exchange(support_changed_, false);
  // Under the sphere model an IR holds for every position of the spheres as long as every
  // node they hold or carry, and every obstacle contact, is one of its row nodes, each
  // pushed along the direction it had at the build (its normal compliance does not depend
  // on where they are): it is rebuilt when one is not, or when a sphere holding nothing
  // comes nearest another triangle.
  const bool sets_changed = update.changed || support_changed || nearest != built_nearest_ ||
                            (sphere_model() && !sphere_irs_stand());
  if (sets_changed || options_.naive_every_step) {
    IncrementalCondensation& condensation = ir_condensation();
    const std::vector<Eigen::Vector3d> held = boundary_displacement(condensation);
    RestDisplacement rest_displacement;  // the support's load at rest, if any
    if (supported_ && supported_->support().loads_at_rest())
      rest_displacement = [support = &supported_->support()](std::span<const int> dofs) {
        return support->rest_displacement(dofs);
      };
    SphereIrSource sphere;
    if (sphere_model()) {
      sphere = {&sphere_solve_->normal_compliance(), sphere_solve_->contact_slots(),
                sphere_solve_->obstacle_rows(), sphere_solve_->obstacle_constraints()};
      if (sets_changed)
        built_sphere_rows_.assign(static_cast<std::size_t>(body_.mesh.node_count()), 0);
    }
    // One user's IR, prepared (and so checked) when the sets changed.
    struct BuiltIr {
      std::shared_ptr<const PreparedIR> ir;
      std::size_t bytes = 0;
    };
    const auto build = [&](std::size_t i) {
      IntermediateRepresentation ir =
          build_ir(body_, condensation, tools, i, held, options_.ir,
                   users_[tools[i].user].epoch + 1, time, rest_displacement, sphere);
      BuiltIr built;
      if (!sets_changed) return built;
      built.bytes = ir.size_bytes();
      built.ir = std::make_shared<const PreparedIR>(prepare_ir(std::move(ir)));
      return built;
    };
    std::vector<BuiltIr> built(tools.size());
    if (sphere_model() && tools.size() > 1) {
      // A sphere IR is cut from W and the body alone (neither the condensation nor a
      // support's load is touched), so the users' IRs are built side by side, one thread per
      // further user, joined here: a rebuild that changes every IR costs about one build.
      std::vector<std::future<BuiltIr>> others;
      for (std::size_t i = 1; i < tools.size(); ++i)
        others.push_back(std::async(std::launch::async, build, i));
      built[0] = build(0);  // should it throw, the futures' destructors join their threads first
      for (std::size_t i = 1; i < tools.size(); ++i) built[i] = others[i - 1].get();
    } else {
      for (std::size_t i = 0; i < tools.size(); ++i)
        built[i] = build(i);  // condense() updates the condensation
    }
    for (std::size_t i = 0; i < tools.size() && sets_changed; ++i) {
      UserState& user = users_[tools[i].user];
      ++user.epoch;
      report.ir_bytes += built[i].bytes;
      if (sphere_model())
        for (const std::int64_t tag : condensed_fem(built[i].ir->ir).node_ids)
          built_sphere_rows_[static_cast<std::size_t>(node_of_tag_.at(tag))] = 1;
      user.ir = std::move(built[i].ir);
      // force() makes its evaluation state when first asked: a P1 session without a view
      // never asks, and the IR leaves for its client without waiting for one.
      p0_states_[static_cast<std::size_t>(tools[i].user)].reset();
    }
    built_nearest_ = nearest;
    if (sphere_model() && sets_changed) {
      built_row_directions_.clear();
      const NormalCompliance& normal = sphere_solve_->normal_compliance();
      for (int node = 0; node < body_.mesh.node_count(); ++node)
        if (const int slot =
                built_sphere_rows_[static_cast<std::size_t>(node)] ? normal.slot_of(node) : -1;
            slot >= 0)
          built_row_directions_.emplace_back(node, normal.normal(slot));
    }
    report.rebuilt = sets_changed;
    report.recomputed = true;
  }
  report.rebuild_ms = update.elapsed_ms + watch.elapsed_ms();
  previous_contacts_ = pressing_contacts();
  previous_spheres_ = spheres();
  report.boundary_nodes = static_cast<int>(condensation_.boundary_nodes().size());
  for (const auto& [node, held] : held_) report.obstacle_nodes += held.obstacle >= 0;
  if (sphere_model()) report.obstacle_nodes = sphere_solve_->obstacle_pushed();
  return report;
}

std::vector<Eigen::Vector3d> Simulation::remote_positions(
    const IntermediateRepresentation& ir) const {
  std::vector<Eigen::Vector3d> positions;
  for (int r = 0; r < remote_count(ir); ++r) {
    const UserState& user = users_[remote_user(ir, r)];
    positions.push_back(user.known
                            ? user.position
                            : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  }
  return positions;
}

ForceSample Simulation::force(int user) {
  const UserState& state = users_[user];
  if (!state.ir) return {};
  // The condensed FEM body ignores dt; the sphere model's state keeps its contact solve.
  std::optional<EvaluationState>& evaluation = p0_states_[static_cast<std::size_t>(user)];
  if (!evaluation) evaluation = make_evaluation_state(*state.ir);
  return evaluate_force(*state.ir, *evaluation, state.position, remote_positions(state.ir->ir), 0);
}

}  // namespace cohaptic
