#include "common/ir/mass_spring_evaluation.h"

#include <fmt/format.h>

#include <cmath>

#include "common/mass_spring/surface_collision.h"
#include "common/util/error.h"

namespace cohaptic {

PreparedMassSpring prepare_mass_spring(const MassSpringIr& ir) {
  const auto nodes = ir.node_ids.size();
  const auto columns = static_cast<std::size_t>(ir.positions.cols());
  if (columns != nodes || static_cast<std::size_t>(ir.velocities.cols()) != nodes ||
      static_cast<std::size_t>(ir.mass.size()) != nodes || ir.held.size() != nodes)
    throw Error(fmt::format(
        "intermediate representation: a mass-spring body of {} nodes with {} positions, {} "
        "velocities, {} masses and {} held flags",
        nodes, columns, ir.velocities.cols(), ir.mass.size(), ir.held.size()));
  if (!ir.velocities.allFinite())
    throw Error("intermediate representation: a mass-spring velocity is not finite");
  if (ir.remote_users.size() != ir.remote_radii.size() ||
      ir.presses.size() != ir.remote_users.size() + 1)
    throw Error(fmt::format(
        "intermediate representation: {} remote users, {} radii and {} presses (expected one more)",
        ir.remote_users.size(), ir.remote_radii.size(), ir.presses.size()));
  if (ir.presses.size() > static_cast<std::size_t>(kMaxNetworkTools))
    throw Error(fmt::format(
        "intermediate representation: {} tools on a mass-spring body, at most {} supported",
        ir.presses.size(), kMaxNetworkTools));
  for (double radius : ir.remote_radii)
    if (!(std::isfinite(radius) && radius >= 0))
      throw Error("intermediate representation: a remote tool radius out of range");
  for (const ToolPress& press : ir.presses)
    if (!press.previous.allFinite())
      throw Error("intermediate representation: a tool's previous position is not finite");
  PreparedMassSpring prepared;
  MassSpringNetwork& network = prepared.network;
  network.rest_positions = ir.positions;
  network.mass = ir.mass;
  network.held = ir.held;
  network.springs = ir.springs;
  network.triangles = ir.triangles;
  network.parameters = ir.parameters;
  // Triangle indices are checked before the surface is indexed by them.
  for (const auto& triangle : network.triangles)
    for (int node : triangle)
      if (node < 0 || static_cast<std::size_t>(node) >= nodes)
        throw Error(fmt::format("intermediate representation: a triangle names node {} of {}", node,
                                nodes));
  index_surface(network);
  check_network(network, "intermediate representation");
  check_node_backing(ir.backing, static_cast<int>(nodes), "intermediate representation");
  return prepared;
}

MassSpringPatchState make_mass_spring_state(const MassSpringIr& ir,
                                            const PreparedMassSpring& prepared) {
  MassSpringPatchState state;
  state.network = make_state(prepared.network);
  state.network.velocities = ir.velocities;
  prepare_backing_solve(state.network.backing, ir.backing);
  for (std::size_t i = 0; i < ir.presses.size(); ++i) state.presses[i] = ir.presses[i];
  return state;
}

NetworkToolReaction advance_mass_spring(const MassSpringIr& ir, const PreparedMassSpring& prepared,
                                        MassSpringPatchState& state,
                                        const Eigen::Vector3d& own_tool, double own_radius,
                                        std::span<const Eigen::Vector3d> remote_tools,
                                        double dt) noexcept {
  if (!(dt > 0) || !std::isfinite(dt)) return {};
  std::array<ToolOnNetwork, kMaxNetworkTools> tools;
  std::array<NetworkToolReaction, kMaxNetworkTools> reactions;
  tools[0] = {own_tool, own_radius};
  std::size_t count = 1;
  for (std::size_t i = 0; i < ir.remote_users.size() && count < tools.size(); ++i, ++count) {
    const Eigen::Vector3d absent = Eigen::Vector3d::Constant(std::nan(""));
    tools[count] = {i < remote_tools.size() ? remote_tools[i] : absent, ir.remote_radii[i]};
  }
  advance_with_tools(prepared.network, state.network, std::span(tools.data(), count),
                     std::span(state.presses.data(), count), std::span(reactions.data(), count), dt,
                     ir.backing.empty() ? nullptr : &ir.backing);
  return reactions[0];
}

}  // namespace cohaptic
