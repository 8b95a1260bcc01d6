#include "common/sim/separation_simulation.h"

#include <algorithm>

#include "common/ir/separation_evaluation.h"
#include "common/util/stopwatch.h"

namespace cohaptic {

SeparationSimulation::SeparationSimulation(const SeparationModel& body, int object,
                                           const std::vector<ToolSpec>& tools, double force_limit)
    : body_(body),
      object_(object),
      force_limit_(force_limit),
      state_(make_separation_state(*body.patch)),
      users_(tools.size()) {
  for (std::size_t u = 0; u < tools.size(); ++u) {
    users_[u].settings.grasp_reach = body.spec.grasp_reach;
    for (const SeparationInstrumentSpec& instrument : body.spec.instruments)
      if (instrument.tool == tools[u].name) users_[u].settings = instrument.settings;
  }
}

void SeparationSimulation::set_tool(int user, const Eigen::Vector3d& position,
                                    std::uint32_t buttons) {
  UserState& state = users_[static_cast<std::size_t>(user)];
  state.known = position.allFinite();
  state.position = position;
  state.buttons = buttons;
}

void SeparationSimulation::clear_tool(int user) {
  users_[static_cast<std::size_t>(user)].known = false;
}

void SeparationSimulation::continue_epochs(int user, std::uint64_t epoch) {
  UserState& state = users_[static_cast<std::size_t>(user)];
  state.epoch = std::max(state.epoch, epoch);
}

bool SeparationSimulation::pressing(int user) const {
  return users_[static_cast<std::size_t>(user)].tool.contact.mode != ContactMode::none;
}

double SeparationSimulation::distance_to_interface(const Eigen::Vector3d& point) const {
  double distance = 0;
  nearest_patch_point(*body_.patch, point, distance);
  return distance;
}

StepReport SeparationSimulation::step(double time) {
  const double dt = started_ ? time - time_ : 0;
  started_ = true;
  time_ = time;
  const SeparationPatch& patch = *body_.patch;
  for (UserState& user : users_) {
    if (!user.known) {
      user.tool = SeparationToolState{};  // an unknown tool holds and fires nothing
      user.force = ForceSample{};
      continue;
    }
    const double before = state_.separated_area;
    const bool firing = user.settings.laser && (user.buttons & kLaserFireButton) != 0;
    user.force = step_separation_force(patch, state_, user.tool, user.settings, user.position,
                                       user.buttons, dt, force_limit_);
    (firing ? vaporised_ : fractured_) += state_.separated_area - before;
  }

  StepReport report;
  report.separates = true;
  report.fractured_m2 = fractured_;
  report.vaporised_m2 = vaporised_;
  report.groove_record_full = state_.groove.full;
  const Stopwatch rebuild;
  for (std::size_t u = 0; u < users_.size(); ++u) {
    const UserState& user = users_[u];
    if (!user.known) continue;
    // A nanosecond's slack: steps at exact multiples of 1/rate are due although their
    // difference rounds a bit short.
    const bool due = !user.ir || time - user.last_ir_time >= 1 / body_.spec.ir_rate_hz - 1e-9;
    if (due && ir_stale(user)) publish_ir(static_cast<int>(u), time, report);
  }
  if (report.rebuilt) report.rebuild_ms = rebuild.elapsed_ms();
  return report;
}

bool SeparationSimulation::ir_stale(const UserState& user) const {
  if (!user.ir) return true;
  const auto& sent = std::get<SeparationIr>(user.ir->ir.body);
  return sent.state.separated_area != state_.separated_area ||
         sent.tool_state.contact.mode != user.tool.contact.mode ||
         sent.tool_state.jaws_closed != user.tool.jaws_closed;
}

void SeparationSimulation::publish_ir(int user, double time, StepReport& report) {
  UserState& state = users_[static_cast<std::size_t>(user)];
  IntermediateRepresentation ir;
  ir.epoch = state.epoch + 1;
  ir.simulation_time = time;
  ir.user = user;
  ir.object = object_;
  ir.force_limit = force_limit_;
  SeparationIr body{body_.patch, state_, state.settings, state.tool};
  report.ir_bytes += body.size_bytes();
  ir.body = std::move(body);
  state.ir = std::make_shared<const PreparedIR>(prepare_ir(std::move(ir)));
  state.epoch += 1;
  state.last_ir_time = time;
  report.rebuilt = true;
  report.recomputed = true;  // the IR was built this step: its time counts as a build
}

}  // namespace cohaptic
