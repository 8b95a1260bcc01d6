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
  Eigen::Matrix3Xd surface_points;
  if (!obstacles.empty()) {
    surface_points = surface_rest_points(body.mesh, body.surface);
    for (const Obstacle& obstacle : obstacles) obstacles_.emplace_back(obstacle, surface_points);
  }
  if (options.ir.contact_model == ContactModel::sphere)
    contacts_.emplace<SphereContacts>(body, columns, obstacles_, users_.size());
  else if (!obstacles_.empty())
    contacts_.emplace<TriangleContacts>(obstacles_, surface_points);
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
  return with_contacts([&](auto& contacts) { return contacts.solve(*this); });
}

StateSolution Simulation::solve_unloaded() {
  return with_contacts([&](auto& contacts) { return contacts.solve_unloaded(*this); });
}

const std::vector<NodeDistance>& Simulation::nodes_near_obstacles() const {
  return with_contacts([](const auto& contacts) -> const std::vector<NodeDistance>& {
    return contacts.near_obstacles();
  });
}

std::vector<SphereTool> Simulation::spheres() const {
  std::vector<SphereTool> out;
  for (const UserState& user : users_)
    if (user.known) out.push_back({user.position, user.radius});
  return out;
}

Eigen::Matrix3Xd Simulation::displacement_of(std::span<const int> nodes) {
  return displacement_of_nodes(columns_, solve(), nodes);
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

bool Simulation::update_boundary() {
  const std::vector<bool>& under_tool = under_tool_;
  const std::vector<bool>& in_patch = in_patch_;
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
        columns_, with_contacts([&](auto& contacts) { return contacts.solve_previous(*this); }),
        fresh);
    for (std::size_t i = 0; i < fresh.size(); ++i)
      hold(fresh[i], {u.col(static_cast<Eigen::Index>(i)), -1});
  } else if (contact_points.empty() && step_delay_held) {
    release_step_delay_nodes();
  }
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
      with_contacts([&](auto& contacts) { contacts.forget(static_cast<int>(u)); });
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
    with_contacts([&](auto& contacts) { contacts.mark(*this, static_cast<int>(u)); });
  }
}

void Simulation::update_held_set() {
  find_contacts();
  Stopwatch watch;
  HeldSetUpdate update;
  update.changed = update_boundary();
  update.changed |= with_contacts([&](auto& contacts) { return contacts.settle(*this, update); });
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
    const int slot = static_cast<int>(u);
    const bool follows_nearest =
        with_contacts([&](const auto& contacts) { return contacts.follows_nearest(slot); });
    nearest.push_back(!user.known ? -1 : follows_nearest ? user.nearest : kHoldingSphere);
    if (user.known)
      tools.push_back(
          {slot, user.position, user.radius, user.nearest,
           with_contacts([&](const auto& contacts) { return contacts.carried(slot); })});
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
  const bool sets_changed =
      update.changed || support_changed || nearest != built_nearest_ ||
      !with_contacts([&](const auto& contacts) { return contacts.irs_stand(*this); });
  if (sets_changed || options_.naive_every_step) {
    IncrementalCondensation& condensation = ir_condensation();
    const std::vector<Eigen::Vector3d> held = boundary_displacement(condensation);
    RestDisplacement rest_displacement;  // the support's load at rest, if any
    if (supported_ && supported_->support().loads_at_rest())
      rest_displacement = [support = &supported_->support()](std::span<const int> dofs) {
        return support->rest_displacement(dofs);
      };
    const SphereIrSource sphere =
        with_contacts([&](auto& contacts) { return contacts.ir_source(*this, sets_changed); });
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
    if (with_contacts(
            [&](const auto& contacts) { return contacts.builds_side_by_side(tools.size()); })) {
      // One thread per further user, joined here: a rebuild that changes every IR costs about
      // one build.
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
      with_contacts([&](auto& contacts) { contacts.built(*this, *built[i].ir); });
      user.ir = std::move(built[i].ir);
      // force() makes its evaluation state when first asked: a P1 session without a view
      // never asks, and the IR leaves for its client without waiting for one.
      p0_states_[static_cast<std::size_t>(tools[i].user)].reset();
    }
    built_nearest_ = nearest;
    if (sets_changed) with_contacts([&](auto& contacts) { contacts.built_all(*this); });
    report.rebuilt = sets_changed;
    report.recomputed = true;
  }
  report.rebuild_ms = update.elapsed_ms + watch.elapsed_ms();
  with_contacts([&](auto& contacts) { contacts.remember_step(*this); });
  report.boundary_nodes = static_cast<int>(condensation_.boundary_nodes().size());
  report.obstacle_nodes =
      with_contacts([&](const auto& contacts) { return contacts.obstacle_nodes(*this); });
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
