#include "common/sim/mass_spring_simulation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "common/ir/build_mass_spring_ir.h"
#include "common/mass_spring/surface_collision.h"
#include "common/util/error.h"
#include "common/util/stopwatch.h"

namespace cohaptic {

MassSpringSimulation::MassSpringSimulation(const MassSpringModel& body, int object,
                                           const std::vector<ToolSpec>& tools, double force_limit,
                                           double period)
    : body_(body),
      object_(object),
      force_limit_(force_limit),
      period_(period),
      state_(make_state(body.network)) {
  if (!(period > 0) || !std::isfinite(period))
    throw Error(fmt::format(
        "mass-spring simulation of '{}': the period must be positive and finite, not {}", body.name,
        period));
  users_.resize(tools.size());
  for (std::size_t u = 0; u < users_.size(); ++u) users_[u].radius = tools[u].radius;
  tools_.resize(tools.size());
  presses_.resize(tools.size());
  reactions_.resize(tools.size());
}

void MassSpringSimulation::set_tool(int user, const Eigen::Vector3d& position) {
  UserState& state = users_[static_cast<std::size_t>(user)];
  state.known = position.allFinite();
  state.position = position;
}

void MassSpringSimulation::clear_tool(int user) {
  users_[static_cast<std::size_t>(user)].known = false;
}

void MassSpringSimulation::continue_epochs(int user, std::uint64_t epoch) {
  UserState& state = users_[static_cast<std::size_t>(user)];
  state.epoch = std::max(state.epoch, epoch);
}

Eigen::Vector3d MassSpringSimulation::tool_position(int user) const {
  const UserState& state = users_[static_cast<std::size_t>(user)];
  return state.known ? state.position
                     : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
}

double MassSpringSimulation::distance_to_surface(const Eigen::Vector3d& point) const {
  double nearest = std::numeric_limits<double>::infinity();
  for (int node : body_.network.surface_nodes)
    nearest = std::min(nearest, (state_.positions.col(node) - point).norm());
  return nearest;
}

StepReport MassSpringSimulation::step(double time) {
  const double period = started_ ? std::clamp(time - time_, 0.0, kMassSpringMaxStepPeriod) : 0;
  started_ = true;
  time_ = time;
  for (std::size_t u = 0; u < users_.size(); ++u)
    tools_[u] = {tool_position(static_cast<int>(u)), users_[u].radius};
  // A nanosecond's slack: a step a period after the previous one advances although the
  // difference of their times rounds a bit short.
  pending_ += period;
  while (pending_ >= period_ - 1e-9) {
    advance_with_tools(body_.network, state_, tools_, presses_, reactions_, period_,
                       backing_.empty() ? nullptr : &backing_);
    pending_ -= period_;
  }
  if (state_.backing.failures > reported_backing_failures_) {
    // Never silently wrong: a failed solve held the last pushes (node_backing.h).
    spdlog::warn(
        "mass-spring object '{}': the contact solve of the body behind it failed in {} of {} "
        "substeps so far "
        "(each held its previous pushes)",
        body_.name, state_.backing.failures, state_.backing.evaluations);
    reported_backing_failures_ = state_.backing.failures;
  }

  StepReport report;
  const Stopwatch rebuild;
  const MassSpringIrSettings& settings = body_.spec.ir;
  for (std::size_t u = 0; u < users_.size(); ++u) {
    UserState& user = users_[u];
    user.pressing = reactions_[u].colliding;
    if (!user.known) continue;
    const bool near =
        user.pressing || distance_to_surface(user.position) - user.radius <= settings.near_distance;
    // A nanosecond's slack: steps at a rate's exact multiples of 1/rate_hz are due although
    // their difference rounds a bit short.
    const bool due = !user.ir || time - user.last_ir_time >= 1 / settings.rate_hz - 1e-9;
    if (near && due) publish_ir(static_cast<int>(u), time, report);
  }
  if (report.rebuilt) report.rebuild_ms = rebuild.elapsed_ms();
  return report;
}

void MassSpringSimulation::publish_ir(int user, double time, StepReport& report) {
  UserState& state = users_[static_cast<std::size_t>(user)];
  const int contact =
      find_surface_contact(body_.network, state_.positions, state.position, state.radius)
          .nearest_node;
  IntermediateRepresentation ir;
  ir.epoch = state.epoch + 1;
  ir.simulation_time = time;
  ir.user = user;
  ir.object = object_;
  ir.tool_radius = state.radius;
  ir.force_limit = force_limit_;
  MassSpringIr body = build_mass_spring_ir(body_, state_, contact, body_.spec.ir.sections);
  body.presses.push_back(presses_[static_cast<std::size_t>(user)]);
  for (int other = 0; other < user_count(); ++other) {
    const UserState& remote = users_[static_cast<std::size_t>(other)];
    if (other == user || !remote.known ||
        body.presses.size() >= static_cast<std::size_t>(kMaxNetworkTools))
      continue;
    body.remote_users.push_back(other);
    body.remote_radii.push_back(remote.radius);
    body.presses.push_back(presses_[static_cast<std::size_t>(other)]);
  }
  if (!backing_.empty())
    body.backing = sub_network_backing(backing_, state_.backing.pushes, body.node_ids);
  report.ir_bytes += body.size_bytes();
  ir.body = std::move(body);
  auto prepared = std::make_shared<const PreparedIR>(prepare_ir(std::move(ir)));
  state.evaluation = make_evaluation_state(*prepared);
  state.ir = std::move(prepared);
  state.epoch += 1;
  state.last_ir_time = time;
  report.rebuilt = true;
  report.recomputed = true;
}

ForceSample MassSpringSimulation::force(int user, double dt) {
  UserState& state = users_[static_cast<std::size_t>(user)];
  if (!state.ir) return {};
  const auto& network = std::get<MassSpringIr>(state.ir->ir.body);
  std::array<Eigen::Vector3d, kMaxNetworkTools> remotes;
  const std::size_t count = network.remote_users.size();
  for (std::size_t r = 0; r < count; ++r) remotes[r] = tool_position(network.remote_users[r]);
  return evaluate_force(*state.ir, state.evaluation, tool_position(user),
                        std::span(remotes.data(), count), dt);
}

}  // namespace cohaptic
