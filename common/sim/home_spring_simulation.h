// HomeSpringSimulation: the server's simulation of one laparoscopy tissue (the laparoscopy
// paper's model: home springs for the force, a local deformation for the eye, decoupled),
// with no threads or sockets.
//
// Per user, an instrument: the shaft from the tool's trocar pivot to its tip (the device's
// position); forceps close their jaws on the tissue while button 0 is held (one increment
// per step, forceps_jaws.h), grasp when both stop on it, and release on button up. Tools
// that are not instruments (no trocar) touch nothing on this body.
//
// IRs: the user's HomeSpringPatch around its contact vertex: the corner nearest the point
// where the shaft's line (from the pivot through the tip, and on) first crosses the rest
// surface, so the patch is there before the tip reaches it; while grasped, around the
// vertex nearest the grasp point, with the grasp. A new IR is built when that vertex or
// the grasp changes (not otherwise: the patch is static, the client evaluates it exactly);
// a shaft whose line misses the surface keeps its last IR.
//
// force() is the P0 force: the client's evaluate_force on the user's IR at the step's tool
// position, advanced by the time since the previous step (a viscous tissue's vertex moves,
// viscous_home_spring.h, and goes on to a new IR's patch). The display deformation
// (displayed(), computed when asked, not every step) dents the rest surface per user whose
// vertex is displaced: P the contact point and A = P + u (the tip, for a probe that holds
// it); P the grasp point, fixed, and A it moved by the pull for grasping forceps; a vertex let
// go of on a viscous tissue goes on denting it while it returns home. The users' dents add.
// Units: SI; times in s of the simulation's clock.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "common/ir/evaluate_force.h"
#include "common/laparoscopy/forceps_jaws.h"
#include "common/laparoscopy/tissue_display.h"
#include "common/model/home_spring_body.h"
#include "common/scene/scene.h"
#include "common/sim/step_report.h"

namespace cohaptic {

/// One pressing user's dent of the displayed tissue: P -> A (see above) [m].
struct TissueDent {
  Eigen::Vector3d from = Eigen::Vector3d::Zero(), to = Eigen::Vector3d::Zero();
};

/// The rest surface of `display` dented by every one of `dents`, the dents added [m].
Eigen::Matrix3Xd dented_surface(const TissueDisplay& display, std::span<const TissueDent> dents);

class HomeSpringSimulation {
 public:
  /// One user per tool; `body` must outlive it. `object` is the body's index in the scene
  /// (the IRs' object); `force_limit` [N] goes into every IR.
  HomeSpringSimulation(const HomeSpringBody& body, int object, const std::vector<ToolSpec>& tools,
                       double force_limit);

  // The members SceneSimulation visits, as Simulation has them.
  int user_count() const { return static_cast<int>(users_.size()); }
  /// `buttons`: bit i is the device's button i held (button 0 closes forceps).
  void set_tool(int user, const Eigen::Vector3d& position, std::uint32_t buttons = 0);
  void clear_tool(int user);  ///< the tool touches nothing, forceps release, until set again
  void continue_epochs(int user, std::uint64_t epoch);  ///< the user's next epoch is above `epoch`
  StepReport step(double time);
  /// Null until the user's shaft first aimed at the tissue.
  std::shared_ptr<const PreparedIR> ir(int user) const {
    return users_[static_cast<std::size_t>(user)].ir;
  }
  /// The tool holds its vertex: the shaft crosses the rest surface (a viscous tissue's vertex
  /// not left deeper), or the forceps grasp.
  bool pressing(int user) const { return users_[static_cast<std::size_t>(user)].pressing; }
  /// P0: the user's IR evaluated at its tool's position in the latest step (zero without an
  /// IR or a tool).
  ForceSample force(int user) const;
  /// The forceps' jaws of `user` as of the latest step (open, for a probe).
  const ForcepsJaws& jaws(int user) const { return users_[static_cast<std::size_t>(user)].jaws; }
  /// The rest surface dented by the users' displaced vertices, as of the latest step [m].
  Eigen::Matrix3Xd displayed() const { return dented_surface(body_.display, dents()); }
  /// The users' dents as of the latest step: what displayed() draws, small to hand
  /// to another thread (the live view dents the surface on its own).
  std::vector<TissueDent> dents() const;
  /// Distance from `point` to the rest surface [m].
  double distance_to_surface(const Eigen::Vector3d& point) const;

  const HomeSpringBody& body() const { return body_; }

 private:
  struct UserState {
    std::optional<InstrumentSpec> instrument;
    bool forceps = false;
    bool known = false;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    std::uint32_t buttons = 0;
    ForcepsJaws jaws;
    bool pressing = false;
    std::optional<TissueDent> dent;  // P -> A while its vertex is displaced
    int centre = -1;                 // surface vertex the IR's patch is built around
    bool grasped = false;            // the IR's grasp
    std::uint64_t epoch = 0;
    std::shared_ptr<const PreparedIR> ir;
    EvaluationState evaluation;  // P0
    EvaluationCarry carry;       // what it hands on to the next IR's (the moving vertex)
    ForceSample force;           // P0 at the latest step
  };
  void step_user(int user, double time, double dt, StepReport& report);
  void evaluate_user(UserState& user, double dt);
  void publish_ir(int user, int centre, double time, StepReport& report);

  const HomeSpringBody& body_;
  int object_;
  double force_limit_;
  double beyond_tip_;  // how far past the tip the shaft's line is followed: across the tissue's
                       // bounds [m]
  std::vector<UserState> users_;
  std::optional<double> previous_time_;  // of the latest step [s]
};

}  // namespace cohaptic
