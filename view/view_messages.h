// The live view's messages (proto/cohaptic/view.proto) built from the server's model and
// simulation: the Scene once, a Frame per view frame, the Status from the users' reports.
// Lengths stay in m and forces in N on the wire; float precision is plenty for drawing.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "cohaptic/view.pb.h"
#include "common/model/model.h"
#include "common/model/shown_surface.h"
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

/// A frame at simulation time `time` [s]: `displacement` of the shown nodes [m], each
/// user's tool, its force evaluated from its IR (Simulation::force), its IR patch and, while
/// it presses, its contact triangle; the held nodes and |B|.
Frame view_frame(const Simulation& simulation, const ShownIndex& index, std::uint64_t sequence, double time,
                 const Eigen::Matrix3Xd& displacement, const std::vector<ToolState>& tools, double sim_rate_hz);

}  // namespace cohaptic::view
