// Simulation: the body of the server's simulation loop, with no threads or sockets.
//
// Each step takes the users' latest tool positions and
//   1. finds every tool's nearest touchable triangle and whether it presses;
//   2. updates the colliding boundary set B: with `step_delay_nodes` = N (the paper's
//      T150/T300), the N surface nodes nearest the pressing tools join B when contact
//      begins, held where they are (at rest), and leave when no tool presses;
//   3. rebuilds every user's IR when a set changed (nearest triangles or B): M~ depends
//      only on the sets, so it is not rebuilt otherwise.
// force() evaluates a user's force from its IR and the current tool positions: the P0
// protocol's server-side force, the same function the P1 client runs.
// Owns the incremental condensation; reads the Model. Units: SI.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "common/condense/incremental_condensation.h"
#include "common/ir/build_ir.h"
#include "common/ir/evaluate_force.h"
#include "common/model/model.h"

namespace cohaptic {

struct SimulationOptions {
  IrBuildOptions ir;
  int step_delay_nodes = 0;  ///< N surface nodes held while any tool presses (0: none)
};

struct StepReport {
  bool rebuilt = false;       ///< the IRs were rebuilt this step
  double rebuild_ms = 0;      ///< time to update B and rebuild every IR
  std::size_t ir_bytes = 0;   ///< total size of the IRs rebuilt
  int boundary_nodes = 0;     ///< |B| after the step
};

class Simulation {
 public:
  /// One user per tool (usually the scene's tools). `model` and `columns` must outlive it.
  Simulation(const Model& model, ComplianceColumns& columns, const std::vector<ToolSpec>& tools,
             SimulationOptions options);

  int user_count() const { return static_cast<int>(users_.size()); }
  void set_tool(int user, const Eigen::Vector3d& position);
  /// The user's tool is no longer known (disconnected): it presses nothing.
  void clear_tool(int user);

  StepReport step(double time);

  /// Latest IR of `user`; null until its tool position is known.
  std::shared_ptr<const PreparedIR> ir(int user) const { return users_[user].ir; }
  /// Reaction force on `user`'s tool now (zero if it has no IR).
  ForceSample force(int user) const;
  /// Positions of the remote tools of `ir`, in its remotes' order (NaN where unknown).
  std::vector<Eigen::Vector3d> remote_positions(const IntermediateRepresentation& ir) const;
  bool pressing(int user) const { return users_[user].pressing; }

  const IncrementalCondensation& condensation() const { return condensation_; }
  const std::vector<Eigen::Vector3d>& boundary_displacement() const { return boundary_displacement_; }

 private:
  struct UserState {
    bool known = false;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    double radius = 0;
    int nearest = -1;
    bool pressing = false;
    std::uint64_t epoch = 0;
    std::shared_ptr<const PreparedIR> ir;
  };
  bool update_boundary();

  const Model& model_;
  SimulationOptions options_;
  IncrementalCondensation condensation_;
  std::vector<Eigen::Vector3d> boundary_displacement_;  // per B node, in condensation order
  std::vector<UserState> users_;
  std::vector<int> built_nearest_;                     // nearest triangles the IRs were built for
  std::vector<int> built_boundary_;
};

}  // namespace cohaptic
