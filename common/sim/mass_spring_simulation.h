// MassSpringSimulation: the server's simulation of one mass–spring body (the thin-objects
// paper's model), with no threads or sockets. The whole network is integrated in real time
// in fixed periods (the haptic loop's, as each client integrates its sub-network): each
// step advances it by as many whole periods as have passed since the previous step, with
// every known user's tool pressing it, and carries the remainder. (Periods that follow the
// server's uneven steps make Eq. (5)'s force kick: a node set moving at d/h by one period
// is stopped in another.)
//
// IRs: while a user's tool is within the body's near_distance of the surface, the user gets
// a fresh IR at the body's IR rate: the sub-network around its nearest surface node
// (build_mass_spring_ir.h) with the server's state, the other known users' tools and every
// tool's press memory, so that the client continues where the server's step left off. The
// server stays authoritative: each IR replaces the client's integrated state. A user far
// from the body keeps its last IR (its tool touches nothing in it).
//
// force() is the P0 protocol's force: the client's evaluation (evaluate_force) run here on
// a server-held evaluation state that each new IR resets, advanced by the caller's period.
// Units: SI; times in s of the simulation's clock.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "common/ir/evaluate_force.h"
#include "common/mass_spring/mass_spring_state.h"
#include "common/mass_spring/node_backing.h"
#include "common/mass_spring/tool_coupling.h"
#include "common/model/mass_spring_body.h"
#include "common/scene/scene.h"
#include "common/sim/step_report.h"

namespace cohaptic {

/// The longest period one step integrates [s]: after a stall the network does not try to
/// catch up seconds of simulated time in one step.
inline constexpr double kMassSpringMaxStepPeriod = 0.05;

class MassSpringSimulation {
 public:
  /// One user per tool; `body` must outlive it. `object` is the body's index in the scene
  /// (the IRs' object); `force_limit` [N] goes into every IR; `period` [s] > 0 is the fixed
  /// period the network is advanced by (the haptic loop's nominal period).
  MassSpringSimulation(const MassSpringModel& body, int object, const std::vector<ToolSpec>& tools,
                       double force_limit, double period);

  // The members SceneSimulation visits, as Simulation has them (set_tool, clear_tool,
  // continue_epochs, step, ir, pressing), and force with the period to advance by.
  int user_count() const { return static_cast<int>(users_.size()); }
  void set_tool(int user, const Eigen::Vector3d& position);
  void clear_tool(int user);  ///< the tool presses nothing until set again
  void continue_epochs(int user, std::uint64_t epoch);  ///< the user's next epoch is above `epoch`
  StepReport step(double time);
  /// Null until the user's tool came near the body.
  std::shared_ptr<const PreparedIR> ir(int user) const {
    return users_[static_cast<std::size_t>(user)].ir;
  }
  bool pressing(int user) const { return users_[static_cast<std::size_t>(user)].pressing; }
  /// P0: advances the user's server-held evaluation of its IR by `dt` [s] at the current
  /// tool positions and returns its force (zero without an IR).
  ForceSample force(int user, double dt);
  /// The whole network's reaction on the user's tool in the latest step: what the user
  /// would feel if the server's own step drove its force (the trade-off's reference).
  const NetworkToolReaction& reaction(int user) const {
    return reactions_[static_cast<std::size_t>(user)];
  }
  /// The body behind this one pressing back on its colliding nodes from the next step on
  /// (SceneSimulation's interactions; an empty backing: nothing behind it).
  void set_backing(NodeBacking backing) {
    backing_ = std::move(backing);
    prepare_backing_solve(state_.backing, backing_);
  }
  const NodeBacking& backing() const { return backing_; }
  /// Distance from `point` to the nearest surface node in the current state [m].
  double distance_to_surface(const Eigen::Vector3d& point) const;

  const MassSpringModel& body() const { return body_; }
  const MassSpringState& state() const { return state_; }

 private:
  struct UserState {
    bool known = false;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    double radius = 0;
    bool pressing = false;
    std::uint64_t epoch = 0;
    double last_ir_time = 0;
    std::shared_ptr<const PreparedIR> ir;
    EvaluationState evaluation;  // P0
  };
  void publish_ir(int user, double time, StepReport& report);
  Eigen::Vector3d tool_position(int user) const;

  const MassSpringModel& body_;
  int object_;
  double force_limit_;
  double period_;       // of each advance [s]
  double pending_ = 0;  // time stepped but not yet advanced [s]
  MassSpringState state_;
  std::vector<UserState> users_;
  std::vector<ToolOnNetwork> tools_;             // per user, for each step
  std::vector<ToolPress> presses_;               // per user: the whole network's contact memory
  std::vector<NetworkToolReaction> reactions_;   // per user, of the latest step
  NodeBacking backing_;                          // the body behind this one, if any
  std::uint64_t reported_backing_failures_ = 0;  // of state_.backing.failures, logged so far
  bool started_ = false;
  double time_ = 0;  // of the latest step [s]
};

}  // namespace cohaptic
