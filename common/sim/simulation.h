// Simulation: the body of the server's simulation loop, with no threads or sockets.
//
// Each step takes the users' latest tool positions and, in named stages,
//   1. contacts: finds every tool's nearest touchable triangle and whether it presses;
//   2. held set: updates the colliding boundary set B, the nodes held at a prescribed
//      displacement:
//      - step delay (the paper's T150/T300): with `step_delay_nodes` = N, the N surface
//        nodes nearest the pressing tools, outside every user's patch, join B when contact
//        begins, held where they were at the previous step (before the touch), and leave
//        when no tool presses;
//      - rigid obstacles, under the translation and point contact models: a surface node
//        whose displaced position penetrates an obstacle joins B, held at its closest point
//        on the obstacle; a held node whose holding force would pull it into the obstacle is
//        released. The active set is iterated up to `obstacle_iterations` times per step
//        (and keeps converging over steps). Under the sphere contact model the obstacles
//        are unilateral constraints of the state solve instead (sphere_state_solve.h): their
//        nodes slide along them, and the IRs carry them as rows of their own;
//      - a node of a tool's nearest triangle is never held: the tool wins (under the
//        sphere contact model, no node of the sphere's patch);
//   3. IRs: rebuilds every user's IR when a set changed (nearest triangles, the nodes each
//      sphere holds under the sphere contact model, or B): M~ depends
//      only on the sets, so it is not rebuilt otherwise (`naive_every_step` computes it
//      every step all the same, for its cost, and publishes it only when a set changed).
// The contact model is chosen once, at construction: the triangle models' state (the
// obstacles' active set, the previous step's contacts) or the sphere model's (its state
// solve, the nodes its spheres hold and carry, what its IRs hold) is one alternative of
// `contacts_`, and every place a step differs between them is a member both alternatives
// have, reached by std::visit, so that a model without one does not compile. What both
// models read (the tools' nearest triangles, B) stays in Simulation.
// force() evaluates a user's force from its IR and the current tool positions: the P0
// protocol's server-side force, the same function the P1 client runs. surface
// displacement() solves the whole state for display.
// step() runs the three; update_held_set() and build_irs() split them for another body
// pressing on this one (an FEM pair, fem_pair_interaction.h), which acts in between: it sets
// loads applied in every state solve, and may set a support (this body's compliance with the
// other body folded in on the nodes that push on it, supported_compliance.h) that the IRs
// condense over from then on; a change of support rebuilds them, as a change of the sets
// does. A copy shares the body and the compliance columns (a cache of what does not change)
// and owns the rest, a support and its condensation included: it steps bit for bit as the
// original would, apart from it (tests/test_simulation_copy.cpp), though not at the same time
// on another thread, as steps fill the shared columns. Units: SI.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <span>
#include <unordered_map>
#include <variant>
#include <vector>

#include "common/condense/incremental_condensation.h"
#include "common/contact/find_contact.h"
#include "common/contact/nearest_triangle_candidates.h"
#include "common/contact/obstacle_clearance.h"
#include "common/contact/obstacle_distance.h"
#include "common/contact/sphere_contact.h"
#include "common/ir/build_ir.h"
#include "common/ir/evaluate_force.h"
#include "common/model/elastic_body.h"
#include "common/sim/sphere_state_solve.h"
#include "common/sim/state_solve.h"
#include "common/sim/step_report.h"
#include "common/sim/supported_compliance.h"

namespace cohaptic {

struct SimulationOptions {
  IrBuildOptions ir;
  int step_delay_nodes = 0;     ///< N surface nodes held while any tool presses (0: none)
  int obstacle_iterations = 4;  ///< active-set passes per step
  /// Free surface nodes about this close to an obstacle are listed by
  /// nodes_near_obstacles() [m].
  double near_obstacle_distance = 0.001;
  /// Compute every M~ from scratch (naive condensation) at every step, as the paper's
  /// conventional simulation loop did: the step delay of large boundary sets then shows.
  bool naive_every_step = false;
};

/// A node and an estimate of its distance to something [m].
struct NodeDistance {
  int node = -1;
  double distance = 0;
};

class Simulation {
 public:
  /// One user per tool (usually the scene's tools). `body` and `columns` (whose rows
  /// must include every node that can be held) must outlive it; the body's surface nodes
  /// collide with `obstacles` (copied into distance queries here).
  Simulation(const ElasticBody& body, std::span<const Obstacle> obstacles,
             ComplianceColumns& columns, const std::vector<ToolSpec>& tools,
             SimulationOptions options);

  int user_count() const { return static_cast<int>(users_.size()); }
  void set_tool(int user, const Eigen::Vector3d& position);
  /// The user's tool is no longer known (disconnected): it presses nothing.
  void clear_tool(int user);
  /// The user's next IR gets an epoch above `epoch` (a user coming from another body).
  void continue_epochs(int user, std::uint64_t epoch);

  /// One step: update_held_set(), then build_irs(time).
  StepReport step(double time);
  /// A step's first two stages: each known tool's contact (its nearest triangle, whether it
  /// presses, a sphere's patch), then the held set B (the tools' triangles freed, the step
  /// delay's nodes, the obstacles' active set, the nodes a sphere's state carries).
  void update_held_set();
  /// A step's last stage, after update_held_set(): every user's IR, built again if a set
  /// changed since the IRs were last built. The step's report. Throws Error if the held set
  /// was not updated since the last build_irs().
  StepReport build_irs(double time);

  /// Step delay from the next step on: hold `nodes` surface nodes while any tool presses (0:
  /// none). The nodes held now are released there and, if a tool presses, chosen afresh.
  void set_step_delay_nodes(int nodes);

  /// Latest IR of `user`; null until its tool position is known.
  std::shared_ptr<const PreparedIR> ir(int user) const {
    return users_[static_cast<std::size_t>(user)].ir;
  }
  /// Reaction force on `user`'s tool now (zero if it has no IR). It advances the user's
  /// evaluation of its IR (a sphere's contact solve is kept from call to call).
  ForceSample force(int user);
  /// Positions of the remote tools of `ir`, in its remotes' order (NaN where unknown).
  std::vector<Eigen::Vector3d> remote_positions(const IntermediateRepresentation& ir) const;
  bool pressing(int user) const { return users_[static_cast<std::size_t>(user)].pressing; }

  /// The whole state solved at the current tool positions, with the applied loads. Not
  /// const, as no solve is: it computes compliance columns and the condensation's cached
  /// rows as it needs them.
  StateSolution solve();
  /// The same without the applied loads: the body as it would be alone.
  StateSolution solve_unloaded();

  /// Loads another body applies to this one, in every state solve from now on.
  void set_applied_loads(AppliedLoads loads) { applied_ = std::move(loads); }
  /// The IRs condense over `support` (built over this body's columns) from the next build on;
  /// null: over the body's own compliance again. Either way they are rebuilt at this step.
  void set_support(std::unique_ptr<SupportedCompliance> support);
  /// The support the IRs condense over, or null: while there is one, their M~ is not of the
  /// body's own L (compliance rows of L would not give it).
  const SupportedCompliance* support() const {
    return supported_ ? &supported_->support() : nullptr;
  }
  /// Displacement of `nodes` (row nodes) in the current state [m].
  Eigen::Matrix3Xd displacement_of(std::span<const int> nodes);

  /// Free surface nodes without compliance columns yet that were about (to first order,
  /// ObstacleClearance::estimate) options.near_obstacle_distance or less from an obstacle
  /// in the last step's last obstacle pass, with that estimate: should one reach the
  /// obstacle, the step that holds it solves its columns first. A caller may have them
  /// solved ahead (the server's CompliancePrefetch). Empty under the sphere contact model.
  const std::vector<NodeDistance>& nodes_near_obstacles() const;

  const IncrementalCondensation& condensation() const { return condensation_; }
  /// u of each node of condensation().boundary_nodes(), in that order [m].
  std::vector<Eigen::Vector3d> boundary_displacement() const;

 private:
  struct UserState {
    bool known = false;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    double radius = 0;
    int nearest = -1;
    std::optional<ToolContact> contact;
    bool pressing = false;
    std::uint64_t epoch = 0;
    std::shared_ptr<const PreparedIR> ir;
  };
  /// What update_held_set() leaves for build_irs().
  struct HeldSetUpdate {
    bool changed = false;           ///< B changed
    double elapsed_ms = 0;          ///< updating B took
    int nodes_outside_patches = 0;  ///< StepReport::sphere_nodes_outside_patches
  };
  /// The support the IRs condense over (set_support) and their condensation over it; a copy
  /// condenses over a copy of the support.
  class CondensationOverSupport {
   public:
    CondensationOverSupport(std::unique_ptr<SupportedCompliance> support, const DofMap& dofs,
                            IncrementalCondensation::Options options)
        : support_(std::move(support)), condensation_(*support_, dofs, options) {}
    CondensationOverSupport(const CondensationOverSupport& other)
        : support_(std::make_unique<SupportedCompliance>(*other.support_)),
          condensation_(other.condensation_, *support_) {}
    CondensationOverSupport& operator=(const CondensationOverSupport&) = delete;

    SupportedCompliance& support() const { return *support_; }
    IncrementalCondensation& condensation() { return condensation_; }

   private:
    std::unique_ptr<SupportedCompliance> support_;  // never null; where condensation_ reads
    IncrementalCondensation condensation_;
  };
  struct HeldNode {
    Eigen::Vector3d displacement = Eigen::Vector3d::Zero();
    int obstacle = -1;  ///< the obstacle holding it, or -1 for a step-delay node
  };

  /// The node translation and point contact models' own part of a step: a tool presses its
  /// nearest triangle, rigid obstacles hold the nodes that reach them in B (an active set),
  /// and the step delay's nodes are held in the previous step's state of pressing contacts.
  /// Each member takes the simulation it is part of (it keeps no pointer to it, so that a
  /// copied simulation's copy is its own).
  class TriangleContacts {
   public:
    TriangleContacts() = default;
    TriangleContacts(std::span<const ObstacleDistance> obstacles,
                     const Eigen::Matrix3Xd& surface_points);
    void forget(int /*user*/) {}
    void mark(Simulation& /*s*/, int /*user*/) {}
    /// After B's update: the obstacles' active-set passes. Whether B changed.
    bool settle(Simulation& s, HeldSetUpdate& update);
    StateSolution solve(Simulation& s) const;
    StateSolution solve_unloaded(Simulation& s) const;
    StateSolution solve_previous(Simulation& s) const;  ///< the previous step's state
    bool follows_nearest(int /*user*/) const { return true; }
    std::vector<int> carried(int /*user*/) const { return {}; }
    bool irs_stand(const Simulation& /*s*/) const { return true; }
    SphereIrSource ir_source(const Simulation& /*s*/, bool /*sets_changed*/) { return {}; }
    bool builds_side_by_side(std::size_t /*tools*/) const { return false; }
    void built(const Simulation& /*s*/, const PreparedIR& /*ir*/) {}
    void built_all(const Simulation& /*s*/) {}
    void remember_step(const Simulation& s);
    int obstacle_nodes(const Simulation& s) const;
    const std::vector<NodeDistance>& near_obstacles() const { return near_obstacles_; }

   private:
    /// One active-set pass: held nodes whose obstacle would pull go free, free nodes that
    /// penetrate one are held on it. Whether B changed.
    bool update_obstacle_contacts(Simulation& s);

    ObstacleClearance clearance_;  // per surface node: where it was last found clear of them
    std::vector<NodeDistance> near_obstacles_;  // see nodes_near_obstacles()
    std::vector<PressingContact> previous_contacts_;
  };

  /// The sphere contact model's own part of a step: each sphere holds the nodes of its patch
  /// it pushes, the obstacles are unilateral constraints of its state solve (kept from step
  /// to step), and an IR stands while it holds every node held, carried or pushed by an
  /// obstacle along the direction it had at the build. Takes its simulation as
  /// TriangleContacts does.
  class SphereContacts {
   public:
    SphereContacts(const ElasticBody& body, ComplianceColumns& columns,
                   std::span<const ObstacleDistance> obstacles, std::size_t users);
    /// The user's tool is not known: it carries nothing.
    void forget(int user) { users_[static_cast<std::size_t>(user)].carried.clear(); }
    /// The user's patch's nodes are under its tool and in its patch (its candidates); it
    /// presses when its sphere holds or carries a node.
    void mark(Simulation& s, int user_slot);
    /// After B's update: nodes the state has a sphere push that its user's patch leaves out
    /// (a bulge carried them in, beyond the rings) join that patch, B is updated again and the
    /// state solved again. Whether B changed; counts in `update` the pushed nodes still left
    /// out after kMaxCarryPasses passes.
    bool settle(Simulation& s, HeldSetUpdate& update);
    StateSolution solve(Simulation& s) { return solve(s, s.spheres()); }
    /// In no FEM pair (refused), so never loaded.
    StateSolution solve_unloaded(Simulation& s) { return solve(s); }
    StateSolution solve_previous(Simulation& s) { return solve(s, previous_spheres_); }
    /// A sphere that holds nothing follows its nearest triangle, so that its IR is there when
    /// it touches; once it holds nodes, their being row nodes is what counts (irs_stand).
    bool follows_nearest(int user) const;
    std::vector<int> carried(int user) const {
      return users_[static_cast<std::size_t>(user)].carried;
    }
    /// Whether the IRs last built stand: they hold every node a sphere holds or carries now
    /// and every obstacle contact, each pushed along its direction at the build.
    bool irs_stand(const Simulation& s) const;
    SphereIrSource ir_source(const Simulation& s, bool sets_changed);
    /// A sphere IR is cut from W and the body alone (neither the condensation nor a support's
    /// load is touched), so the users' IRs are built side by side.
    bool builds_side_by_side(std::size_t tools) const { return tools > 1; }
    void built(const Simulation& s, const PreparedIR& ir);
    void built_all(const Simulation& s);
    void remember_step(const Simulation& s) { previous_spheres_ = s.spheres(); }
    int obstacle_nodes(const Simulation& /*s*/) const { return solve_.obstacle_pushed(); }
    const std::vector<NodeDistance>& near_obstacles() const;

   private:
    struct User {
      std::vector<int> holds;  ///< the nodes its sphere holds at rest
      /// Nodes outside its sphere at rest that the state has it push and that its patch
      /// would not hold otherwise; their triangles join the patch.
      std::vector<int> carried;
      std::vector<int> patch_nodes;  ///< its patch's nodes without the carried nodes' triangles
      std::vector<int> nodes;        ///< its patch's nodes with them: its candidates
    };
    StateSolution solve(Simulation& s, std::span<const SphereTool> spheres);

    SphereStateSolve solve_;                             // kept step to step
    std::unordered_map<std::int64_t, int> node_of_tag_;  // to read the IRs' row nodes
    std::vector<User> users_;
    std::vector<char> built_rows_;  // per node: a row node of the IRs last built
    /// Those rows' nodes with a slot, ascending, and its direction then.
    std::vector<std::pair<int, Eigen::Vector3d>> built_row_directions_;
    std::vector<SphereTool> previous_spheres_;  // the spheres of the previous step
  };

  /// Runs `f` on the contact model's part of the step.
  template <class F>
  decltype(auto) with_contacts(F&& f) {
    return std::visit(std::forward<F>(f), contacts_);
  }
  template <class F>
  decltype(auto) with_contacts(F&& f) const {
    return std::visit(std::forward<F>(f), contacts_);
  }

  /// The contacts stage: each known tool's nearest triangle, whether it presses, a sphere's
  /// patch; the nodes under the tools and in their patches (under_tool_, in_patch_).
  void find_contacts();
  std::vector<PressingContact> pressing_contacts() const;
  StateSolution solve(std::span<const PressingContact> contacts);
  void release_step_delay_nodes();
  std::vector<SphereTool> spheres() const;  ///< every known user's tool
  /// B after the tools' contacts: their triangles' nodes freed, the step delay's nodes held
  /// or released. Whether B changed.
  bool update_boundary();
  /// The condensation the IRs are built over: the support's, with B synchronised, or the body's.
  IncrementalCondensation& ir_condensation();
  std::vector<Eigen::Vector3d> boundary_displacement(
      const IncrementalCondensation& condensation) const;
  void hold(int node, const HeldNode& held);
  void release(int node);
  Eigen::VectorXd boundary_dof_displacement() const;

  const ElasticBody& body_;
  ComplianceColumns& columns_;
  SimulationOptions options_;
  bool step_delay_changed_ = false;  // set_step_delay_nodes() since the last step
  IncrementalCondensation condensation_;
  std::vector<ObstacleDistance> obstacles_;
  NearestTriangleCandidates
      candidates_;  // the few triangles each tool's nearest-triangle scans visit
  std::vector<int> surface_candidates_,
      touchable_candidates_;              // their scratch, reused step to step
  std::vector<bool> touchable_triangle_;  // per surface triangle
  std::unordered_map<int, HeldNode> held_;
  std::vector<UserState> users_;
  std::vector<int> built_nearest_;  // nearest triangles the IRs were built for
  std::variant<TriangleContacts, SphereContacts> contacts_;  // the contact model's part
  std::vector<std::optional<EvaluationState>>
      p0_states_;  // per user: force()'s evaluation of its IR, made at its first call
  // step()'s scratch: the known tools, their nearest triangles (kHoldingSphere for a sphere
  // holding nodes), the nodes under them and in their patches.
  std::vector<UserTool> step_tools_;
  std::vector<int> step_nearest_;
  std::vector<bool> under_tool_, in_patch_;
  bool boundary_dirty_ = false;
  AppliedLoads applied_;                              // see set_applied_loads
  std::optional<HeldSetUpdate> held_set_update_;      // until build_irs()
  std::optional<CondensationOverSupport> supported_;  // see set_support
  bool support_changed_ = false;                      // since the IRs were last built
};

}  // namespace cohaptic
