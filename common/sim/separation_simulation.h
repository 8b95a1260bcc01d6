// SeparationSimulation: the server's simulation of one separating-tissue body (the
// separation-forces paper's model), with no threads or sockets. It holds the authoritative
// separated state: each step moves every known user's instrument (grasp, fracture, laser,
// step_separation_force: the clients' own function) over the time since the previous step,
// the users one after another on the one state. Fracture and vaporisation are decided here.
//
// IRs: a user whose tool is known gets an IR (the whole patch, the separated state and its
// instrument's state, separation_ir.h) when it has none, and again, at most ir_rate_hz
// times a second, when the separated area, its grasp or its jaws changed since the last:
// the client then continues from the server's state.
//
// force() is the P0 force: the latest step's, from the same function the client runs.
// Units: SI; times in s of the simulation's clock.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "common/ir/evaluate_force.h"
#include "common/model/separation_body.h"
#include "common/scene/scene.h"
#include "common/sim/step_report.h"

namespace cohaptic {

class SeparationSimulation {
 public:
  /// One user per tool; `body` must outlive it. `object` is the body's index in the scene
  /// (the IRs' object); `force_limit` [N] goes into every IR.
  SeparationSimulation(const SeparationModel& body, int object, const std::vector<ToolSpec>& tools,
                       double force_limit);

  // The members SceneSimulation visits, as Simulation has them.
  int user_count() const { return static_cast<int>(users_.size()); }
  void set_tool(int user, const Eigen::Vector3d& position, std::uint32_t buttons);
  void clear_tool(int user);  ///< the tool lets go and fires nothing until set again
  void continue_epochs(int user, std::uint64_t epoch);  ///< the user's next epoch is above `epoch`
  StepReport step(double time);
  /// Null until the user's tool was known at a step.
  std::shared_ptr<const PreparedIR> ir(int user) const {
    return users_[static_cast<std::size_t>(user)].ir;
  }
  /// The user's instrument holds the tissue (a grasp, or a pushing tool's push).
  bool pressing(int user) const;
  /// P0: the latest step's force on the user's tool (zero before its first).
  ForceSample force(int user) const { return users_[static_cast<std::size_t>(user)].force; }
  /// Distance from `point` to the interface [m].
  double distance_to_interface(const Eigen::Vector3d& point) const;

  const SeparationModel& body() const { return body_; }
  const SeparationState& state() const { return state_; }
  const SeparationToolSettings& instrument(int user) const {
    return users_[static_cast<std::size_t>(user)].settings;
  }
  double fractured_area() const {
    return fractured_;
  }  ///< separated by the tools' forces so far [m^2]
  double vaporised_area() const { return vaporised_; }  ///< separated by the laser so far [m^2]

 private:
  struct UserState {
    SeparationToolSettings settings;
    bool known = false;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    std::uint32_t buttons = 0;
    SeparationToolState tool;
    ForceSample force;
    std::uint64_t epoch = 0;
    double last_ir_time = 0;
    std::shared_ptr<const PreparedIR> ir;
  };
  bool ir_stale(const UserState& user) const;
  void publish_ir(int user, double time, StepReport& report);

  const SeparationModel& body_;
  int object_;
  double force_limit_;
  SeparationState state_;
  std::vector<UserState> users_;
  double fractured_ = 0;
  double vaporised_ = 0;
  bool started_ = false;
  double time_ = 0;  // of the latest step [s]
};

}  // namespace cohaptic
