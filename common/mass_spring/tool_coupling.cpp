#include "common/mass_spring/tool_coupling.h"

#include <algorithm>
#include <cmath>

#include "common/mass_spring/plane_friction.h"
#include "common/mass_spring/surface_collision.h"

namespace cohaptic {

int substeps_for(const MassSpringNetwork& network, double period) noexcept {
  const double steps = std::ceil(period / network.parameters.time_step * (1 - 1e-12));
  return std::isfinite(steps) ? std::clamp(static_cast<int>(steps), 1, 1'000'000) : 1;
}

void advance_with_tools(const MassSpringNetwork& network, MassSpringState& state,
                        std::span<const ToolOnNetwork> tools, std::span<ToolPress> presses,
                        std::span<NetworkToolReaction> reactions, double period,
                        const NodeBacking* backing) noexcept {
  const std::size_t count = std::min(tools.size(), static_cast<std::size_t>(kMaxNetworkTools));
  std::array<NodeDrive, kMaxNetworkTools> drives;
  std::array<Eigen::Vector3d, kMaxNetworkTools> start, displacement, applied;
  std::array<int, kMaxNetworkTools> tool_of_drive{};
  std::size_t driven = 0;
  for (std::size_t i = 0; i < count; ++i) {
    reactions[i] = NetworkToolReaction{};
    const ToolOnNetwork& tool = tools[i];
    if (!tool.position.allFinite() || !std::isfinite(tool.radius)) {
      presses[i].pressing = false;
      continue;
    }
    const SurfaceContact contact =
        find_surface_contact(network, state.positions, tool.position, tool.radius);
    if (!contact.colliding || network.held[static_cast<std::size_t>(contact.nearest_node)]) {
      presses[i].pressing = false;
      continue;
    }
    const Eigen::Vector3d& n = contact.normal;
    Eigen::Vector3d d = -contact.depth * n;
    if (presses[i].pressing) {
      const Eigen::Vector3d moved = tool.position - presses[i].previous;
      d += moved - moved.dot(n) * n;
    }
    presses[i] = {true, tool.position};
    reactions[i].colliding = true;
    reactions[i].node = contact.nearest_node;
    reactions[i].depth = contact.depth;
    const auto node_taken = [&](std::size_t j) { return drives[j].node == contact.nearest_node; };
    bool taken = false;
    for (std::size_t j = 0; j < driven; ++j) taken = taken || node_taken(j);
    if (taken) continue;
    start[driven] = state.positions.col(contact.nearest_node);
    displacement[driven] = d;
    drives[driven].node = contact.nearest_node;
    drives[driven].normal = n;
    tool_of_drive[driven] = static_cast<int>(i);
    ++driven;
  }

  const int steps = substeps_for(network, period);
  const double h = period / steps;
  std::array<Eigen::Vector3d, kMaxNetworkTools> total;
  for (auto& f : total) f.setZero();
  const std::span<const NodeDrive> active(drives.data(), driven);
  for (int step = 1; step <= steps; ++step) {
    for (std::size_t j = 0; j < driven; ++j) {
      drives[j].target = start[j] + displacement[j] * (static_cast<double>(step) / steps);
      if (network.parameters.plane) {
        const SupportPlane& plane = *network.parameters.plane;
        const double below = height_above(plane, drives[j].target);
        if (below < 0) drives[j].target -= below * plane.normal;
      }
    }
    step_network(network, state, active, std::span(applied.data(), driven), h, backing);
    for (std::size_t j = 0; j < driven; ++j) total[j] += applied[j];
  }
  for (std::size_t j = 0; j < driven; ++j) {
    NetworkToolReaction& reaction = reactions[static_cast<std::size_t>(tool_of_drive[j])];
    reaction.force = -total[j] / steps;
  }
}

}  // namespace cohaptic
