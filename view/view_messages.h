// The live view's messages (proto/cohaptic/view.proto) built from the server's model and
// simulation: the Scene once, a Frame per view frame, the Status from the users' reports.
// Every body of the scene is shown (shown_scene.h). A frame is built in two halves:
// frame_state() takes what it shows from the simulation after a step (small: the tools,
// forces, IRs and each body's BodyFrameState, no displacement), on the simulation thread;
// view_frame() computes the surface's displacement from those and encodes it, on the
// view's own thread.
// Lengths stay in m and forces in N on the wire; float precision is plenty for drawing.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cohaptic/view.pb.h"
#include "common/model/model.h"
#include "common/sim/scene_simulation.h"
#include "view/body_frame_state.h"
#include "view/shown_scene.h"

namespace cohaptic::view {

/// Where each user's tool is, as the simulation step used it.
struct ToolState {
  bool present = false;                                ///< joined, and its tool known and fresh
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< [m]
};

/// The scene: `shown` (model's, at rest, with each object's name, model and shown nodes, and
/// each separating object's interface), the tools, the obstacles (a plane as a square of
/// twice the shown surface's size around its projection), and the session's settings.
Scene view_scene(const Model& model, const ShownScene& shown, wire::Protocol protocol,
                 const record::InjectedDelays& injected, double frame_rate_hz,
                 const std::string& source);

/// One user as a frame shows it.
struct UserFrameState {
  ToolState tool;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< the force the server has for it [N]
  bool pressing = false;
  std::shared_ptr<const PreparedIR> ir;  ///< its latest (immutable, shared with the simulation)
  int body = -1;                         ///< the body it is on
  int contact_node = -1;  ///< on a mass-spring body, while it presses: the node its tool drives
};

/// What a frame shows of the simulation after a step.
struct FrameState {
  std::vector<UserFrameState> users;
  std::vector<BodyFrameState> bodies;  ///< per model body
};

/// Takes a frame's state (simulation thread): each user's tool as `tools` says, its force
/// (`forces`, per user: what P0 sends, Simulation::force), contact and IR; each body's state
/// (`columns` and `states`: per body, its compliance columns and solve_elastic_states()'s).
FrameState frame_state(const SceneSimulation& simulation,
                       std::span<ComplianceColumns* const> columns,
                       const std::vector<std::optional<StateSolution>>& states,
                       const std::vector<ToolState>& tools,
                       std::span<const Eigen::Vector3d> forces);

/// A frame at simulation time `time` [s] (any thread): the displacement of the shown nodes,
/// each user's tool, its force, its IR patch (linear elastic, mass-spring and tissue IRs) and,
/// while it presses, its contact (a linear elastic body's contact triangle, the mass-spring
/// node its tool drives); the held nodes and |B| of the linear elastic bodies; each separating
/// body's separated shares and grooves.
Frame view_frame(const FrameState& state, const ShownScene& shown, std::uint64_t sequence,
                 double time, double sim_rate_hz);

}  // namespace cohaptic::view
