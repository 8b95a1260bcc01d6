// The live view's messages (proto/cohaptic/view.proto) built from the server's model and
// simulation: the Scene once, a Frame per view frame, the Status from the users' reports.
// A frame is built in two halves: frame_state() takes what it shows from the simulation
// after a step (small: the tools, forces, IRs, held nodes and the state's loads, no
// displacement), on the simulation thread; view_frame() computes the surface's
// displacement from those loads and encodes it, on the view's own thread.
// Lengths stay in m and forces in N on the wire; float precision is plenty for drawing.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "cohaptic/view.pb.h"
#include "common/model/model.h"
#include "common/model/shown_surface.h"
#include "common/sim/loaded_columns.h"
#include "common/sim/simulation.h"

namespace cohaptic::view {

/// Where each user's tool is, as the simulation step used it.
struct ToolState {
  bool present = false;                          ///< joined, and its tool known and fresh
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< [m]
};

/// The scene: the shown surface of `body` (one of `model`'s) at rest, the tools, the obstacles (a plane as a square of
/// twice the object's size around the object's projection), and the session's settings.
Scene view_scene(const Model& model, const ElasticBody& body, const ShownSurface& shown, wire::Protocol protocol, const record::InjectedDelays& injected,
                 double frame_rate_hz, const std::string& source);

/// Maps the simulation's nodes to the shown surface's: by volume index, or by mesh tag
/// (as IRs name their nodes).
class ShownIndex {
 public:
  ShownIndex(const ElasticBody& body, const ShownSurface& shown);
  /// The shown index of volume node `node`, or -1.
  int of_node(int node) const { return shown_.index_of[static_cast<std::size_t>(node)]; }
  /// The shown index of the node with mesh tag `tag`, or -1.
  int of_tag(std::int64_t tag) const;

 private:
  const ShownSurface& shown_;
  std::unordered_map<std::int64_t, int> node_of_tag_;
};

/// One user as a frame shows it.
struct UserFrameState {
  ToolState tool;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< evaluated from its IR (Simulation::force) [N]
  bool pressing = false;
  std::shared_ptr<const PreparedIR> ir;             ///< its latest (immutable, shared with the simulation)
};

/// What a frame shows of the simulation after a step.
struct FrameState {
  std::vector<UserFrameState> users;
  std::vector<int> held_nodes;      ///< B, the condensation's boundary nodes (volume indices)
  std::vector<LoadedColumn> loads;  ///< the solved state's forces, for the displacement
};

/// Takes a frame's state (simulation thread): each user's tool as `tools` says, its force,
/// contact and IR; the held nodes; `loads`, the loaded_columns() of simulation.solve().
FrameState frame_state(const Simulation& simulation, std::vector<LoadedColumn> loads, const std::vector<ToolState>& tools);

/// A frame at simulation time `time` [s] (any thread): the displacement of the shown nodes
/// (`row_positions`: their ComplianceColumns::row_position) under the state's loads, each
/// user's tool, its force, its IR patch and, while it presses, its contact triangle; the held
/// nodes and |B|.
Frame view_frame(const FrameState& state, const ShownIndex& index, std::span<const int> row_positions,
                 std::uint64_t sequence, double time, double sim_rate_hz);

}  // namespace cohaptic::view
