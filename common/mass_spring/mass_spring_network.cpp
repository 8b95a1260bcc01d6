#include "common/mass_spring/mass_spring_network.h"

#include <fmt/format.h>

#include <cmath>

#include "common/util/error.h"

namespace cohaptic {

void index_surface(MassSpringNetwork& network) {
  const int nodes = network.node_count();
  std::vector<int> count(static_cast<std::size_t>(nodes) + 1, 0);
  for (const auto& triangle : network.triangles)
    for (int node : triangle) ++count[static_cast<std::size_t>(node) + 1];
  for (int n = 0; n < nodes; ++n)
    count[static_cast<std::size_t>(n) + 1] += count[static_cast<std::size_t>(n)];
  network.node_triangle_start = count;
  network.node_triangles.assign(network.triangles.size() * 3, 0);
  std::vector<int> next(count.begin(), count.end() - 1);
  for (int t = 0; t < static_cast<int>(network.triangles.size()); ++t)
    for (int node : network.triangles[static_cast<std::size_t>(t)])
      network.node_triangles[static_cast<std::size_t>(next[static_cast<std::size_t>(node)]++)] = t;
  network.surface_nodes.clear();
  for (int n = 0; n < nodes; ++n)
    if (count[static_cast<std::size_t>(n) + 1] > count[static_cast<std::size_t>(n)])
      network.surface_nodes.push_back(n);
}

void check_network(const MassSpringNetwork& network, const char* what) {
  const int nodes = network.node_count();
  if (nodes == 0)
    throw Error(fmt::format("{}: a mass-spring network needs at least one node", what));
  if (network.rest_positions.cols() != nodes || static_cast<int>(network.held.size()) != nodes)
    throw Error(fmt::format("{}: {} masses, {} positions and {} held flags", what, nodes,
                            network.rest_positions.cols(), network.held.size()));
  for (int n = 0; n < nodes; ++n) {
    if (!(network.mass[n] > 0) || !std::isfinite(network.mass[n]))
      throw Error(fmt::format("{}: node {} has mass {} (expected a positive mass)", what, n,
                              network.mass[n]));
    if (!network.rest_positions.col(n).allFinite())
      throw Error(fmt::format("{}: node {} has a non-finite position", what, n));
  }
  for (std::size_t s = 0; s < network.springs.size(); ++s) {
    const Spring& spring = network.springs[s];
    if (spring.a < 0 || spring.b < 0 || spring.a >= nodes || spring.b >= nodes ||
        spring.a == spring.b)
      throw Error(fmt::format("{}: spring {} joins nodes {} and {} (of {})", what, s, spring.a,
                              spring.b, nodes));
    if (!(spring.rest_length > 0) || !(spring.stiffness >= 0) || !(spring.damping >= 0) ||
        !std::isfinite(spring.rest_length + spring.stiffness + spring.damping))
      throw Error(fmt::format("{}: spring {} has rest length {}, stiffness {}, damping {}", what, s,
                              spring.rest_length, spring.stiffness, spring.damping));
  }
  for (std::size_t t = 0; t < network.triangles.size(); ++t)
    for (int node : network.triangles[t])
      if (node < 0 || node >= nodes)
        throw Error(fmt::format("{}: triangle {} names node {} (of {})", what, t, node, nodes));
  if (network.node_triangle_start.size() != static_cast<std::size_t>(nodes) + 1 ||
      network.node_triangles.size() != network.triangles.size() * 3)
    throw Error(fmt::format("{}: the surface is not indexed (index_surface)", what));
  const MassSpringParameters& p = network.parameters;
  if (!p.gravity.allFinite() || !(p.node_damping >= 0) || !(p.tool_friction >= 0) ||
      !(p.time_step > 0) || !std::isfinite(p.node_damping + p.tool_friction + p.time_step))
    throw Error(
        fmt::format("{}: gravity, node damping {}, tool friction {} or time step {} out of range",
                    what, p.node_damping, p.tool_friction, p.time_step));
  if (p.plane) {
    const SupportPlane& plane = *p.plane;
    if (!plane.point.allFinite() || !(std::abs(plane.normal.norm() - 1) < 1e-9) ||
        !(plane.dynamic_friction >= 0) || !(plane.static_friction >= plane.dynamic_friction) ||
        !std::isfinite(plane.static_friction))
      throw Error(fmt::format(
          "{}: the plane needs a unit normal and 0 <= dynamic <= static friction", what));
  }
}

}  // namespace cohaptic
