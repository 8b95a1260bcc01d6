// SceneSimulation: the server's simulation of a whole scene, one body simulation per scene
// object (BodySimulation: the condensed FEM body's Simulation, a MassSpringSimulation, a
// HomeSpringSimulation or a SeparationSimulation),
// with no threads or sockets. It is what the server loop and the replay step. A copy shares
// the model and the compliance columns and owns every body's state: it steps bit for bit as
// the original would, whichever runs first (one at a time: steps fill the shared columns).
//
// Each user is on one body at a time: the body whose touchable surface is nearest its tool
// (the FEM body's at rest, a dynamic body's in its current state). A user changes body only
// while it presses nothing, so a tool between two bodies does not flip-flop; its tool is
// given to its body and cleared on the others, so users on different bodies do not couple.
// The IR handed for a user (ir(user)) is its body's latest, with epochs that keep rising
// across a change of body. force() is the P0 force: the same evaluation the client runs.
// The scene's interactions (a mass-spring body pressing on a linear elastic one behind it,
// body_interaction.h) run at the start of each step, before the bodies advance: the
// front body then integrates the behind body's reaction as a backing (node_backing.h).
// A linear elastic body pressing on another (an FEM pair, fem_pair_interaction.h) runs
// between the front body's stages, once its tools' contacts and held set are known and
// before its IRs are built (Simulation::update_held_set, build_irs): both bodies are loaded
// by the pushes and the front body's IRs condense over B folded in as a support.
// Units: SI; times in s of the simulation's clock.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <span>
#include <variant>
#include <vector>

#include "common/kinds/body_kinds.h"
#include "common/model/model.h"
#include "common/sim/body_interaction.h"
#include "common/sim/fem_pair_interaction.h"
#include "common/sim/home_spring_simulation.h"
#include "common/sim/mass_spring_simulation.h"
#include "common/sim/separation_simulation.h"
#include "common/sim/simulation.h"

namespace cohaptic {

/// What a body's step changes: one alternative per body kind (common/kinds/body_kinds.h).
using BodySimulation =
    PerKind<ForKind<LinearElasticKind, Simulation>, ForKind<MassSpringKind, MassSpringSimulation>,
            ForKind<HomeSpringKind, HomeSpringSimulation>,
            ForKind<SeparationKind, SeparationSimulation>>::variant;

class SceneSimulation {
 public:
  /// One user per tool. columns[i] holds body i's compliance columns when it is linear
  /// elastic (rows as Simulation requires), null otherwise; `model` and the columns must
  /// outlive it. `options` applies to the FEM bodies.
  SceneSimulation(const Model& model, std::span<ComplianceColumns* const> columns,
                  const std::vector<ToolSpec>& tools, const SimulationOptions& options);

  int user_count() const { return static_cast<int>(users_.size()); }
  int body_count() const { return static_cast<int>(bodies_.size()); }
  /// The user's tool tip [m] and device buttons (bit i = button i), given to the body it is on
  /// at the next step: a body whose tools use buttons (an instrument's jaws, a laser) has
  /// set_tool(user, position, buttons); the others take the position alone.
  void set_tool(int user, const Eigen::Vector3d& position, std::uint32_t buttons = 0);
  /// The user's tool is no longer known (disconnected): it presses nothing.
  void clear_tool(int user);

  StepReport step(double time);
  /// Every FEM body's step delay from the next step on (Simulation::set_step_delay_nodes).
  void set_step_delay_nodes(int nodes);

  /// The user's latest IR; null until its body built one.
  std::shared_ptr<const PreparedIR> ir(int user) const {
    return users_[static_cast<std::size_t>(user)].ir;
  }
  /// True if ir(user) changed in the latest step.
  bool ir_changed(int user) const { return users_[static_cast<std::size_t>(user)].changed; }
  /// P0: the reaction force on `user`'s tool now, from its IR (zero without one). A dynamic
  /// body's server-held evaluation advances by the latest step's period.
  ForceSample force(int user);
  bool pressing(int user) const;
  /// The body `user` is on.
  int body_of(int user) const { return users_[static_cast<std::size_t>(user)].body; }

  const BodySimulation& body(int i) const { return bodies_[static_cast<std::size_t>(i)]; }
  BodySimulation& body(int i) { return bodies_[static_cast<std::size_t>(i)]; }
  /// The FEM simulation of a scene whose only object is linear elastic (the display and the
  /// live view show that body); throws Error (single_elastic_body's) otherwise.
  const Simulation& single_elastic() const;
  Simulation& single_elastic();
  /// The scene's interactions in scene order, as of the latest step.
  const std::vector<BodyInteraction>& interactions() const { return interactions_; }
  /// The scene's FEM pairs in scene order, as of the latest step.
  int fem_pair_count() const { return static_cast<int>(fem_pairs_.size()); }
  const FemPairInteraction& fem_pair(int i) const {
    return fem_pairs_[static_cast<std::size_t>(i)];
  }
  /// True when `body`'s IRs condense over a support (the front of an FEM pair that pushes):
  /// their M~ is not of the body's own compliance.
  bool condenses_over_support(int body) const;

 private:
  struct UserState {
    bool known = false;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    std::uint32_t buttons = 0;
    int body = 0;
    std::shared_ptr<const PreparedIR> ir;
    bool changed = false;
  };
  void add_fem_pair(const InteractionSpec& spec, int front, int behind,
                    const SimulationOptions& options);
  void assign_bodies();
  void run_interactions();
  /// The FEM pair's step between its front body's stages: the pushes as loads on both
  /// bodies, and the front's support.
  void couple(FemPairInteraction& pair);
  /// An FEM body's step, with the pairs it is the front of acting between its stages.
  StepReport step_fem_body(int body, Simulation& simulation, double time);
  double distance_to_body(int body, const Eigen::Vector3d& point) const;

  const Model& model_;
  std::vector<BodySimulation> bodies_;
  std::vector<UserState> users_;
  std::vector<ComplianceColumns*> columns_;  // per body, null unless linear elastic
  std::vector<BodyInteraction> interactions_;
  std::vector<FemPairInteraction> fem_pairs_;
  bool started_ = false;
  double time_ = 0;    // of the latest step [s]
  double period_ = 0;  // of the latest step [s]
};

}  // namespace cohaptic
