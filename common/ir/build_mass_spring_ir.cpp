#include "common/ir/build_mass_spring_ir.h"

#include <fmt/format.h>

#include <algorithm>

#include "common/util/error.h"

namespace cohaptic {

MassSpringIr build_mass_spring_ir(const MassSpringModel& body, const MassSpringState& state, int contact_node,
                                  int sections) {
  const MassSpringNetwork& network = body.network;
  if (contact_node < 0 || contact_node >= network.node_count())
    throw Error(fmt::format("mass-spring IR of '{}': contact node {} of {}", body.name, contact_node, network.node_count()));
  const int centre = body.section_of_node[static_cast<std::size_t>(contact_node)];
  const int first_free = std::max(centre - sections, 0), last_free = std::min(centre + sections, body.section_count - 1);
  const int first = std::max(first_free - 1, 0), last = std::min(last_free + 1, body.section_count - 1);

  MassSpringIr ir;
  std::vector<int> local(static_cast<std::size_t>(network.node_count()), -1);
  for (int n = 0; n < network.node_count(); ++n) {
    const int section = body.section_of_node[static_cast<std::size_t>(n)];
    if (section < first || section > last) continue;
    local[static_cast<std::size_t>(n)] = static_cast<int>(ir.node_ids.size());
    ir.node_ids.push_back(n);
    const bool rim = section < first_free || section > last_free;
    ir.held.push_back(rim || network.held[static_cast<std::size_t>(n)] ? 1 : 0);
  }
  const auto count = static_cast<Eigen::Index>(ir.node_ids.size());
  ir.positions.resize(3, count);
  ir.velocities.resize(3, count);
  ir.mass.resize(count);
  for (Eigen::Index i = 0; i < count; ++i) {
    const int n = ir.node_ids[static_cast<std::size_t>(i)];
    ir.positions.col(i) = state.positions.col(n);
    ir.velocities.col(i) = state.velocities.col(n);
    ir.mass[i] = network.mass[n];
  }
  const auto inside = [&](int n) { return local[static_cast<std::size_t>(n)]; };
  for (const Spring& spring : network.springs)
    if (inside(spring.a) >= 0 && inside(spring.b) >= 0) {
      Spring copy = spring;
      copy.a = inside(spring.a);
      copy.b = inside(spring.b);
      ir.springs.push_back(copy);
    }
  for (const auto& triangle : network.triangles)
    if (inside(triangle[0]) >= 0 && inside(triangle[1]) >= 0 && inside(triangle[2]) >= 0)
      ir.triangles.push_back({inside(triangle[0]), inside(triangle[1]), inside(triangle[2])});
  ir.parameters = network.parameters;
  return ir;
}

}  // namespace cohaptic
