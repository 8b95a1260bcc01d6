#include "common/model/mass_spring_body.h"

#include <fmt/format.h>

#include "common/mass_spring/stable_time_step.h"
#include "common/model/elastic_body.h"
#include "common/scene/load_scene.h"
#include "common/util/error.h"

namespace cohaptic {

MassSpringModel build_mass_spring_body(const std::string& name, const MassSpringObjectSpec& spec,
                                       const std::string& where) {
  MassSpringModel body;
  body.name = name;
  body.spec = spec;
  try {
    if (spec.lattice) {
      SpringLattice lattice = spring_lattice(*spec.lattice);
      body.network = std::move(lattice.network);
      body.section_of_node = std::move(lattice.section_of_node);
      body.section_count = lattice.section_count;
    } else {
      body.network = tube_network(spec.tube, spec.material);
      body.section_count = spec.tube.sections;
      for (int n = 0; n < body.network.node_count(); ++n)
        body.section_of_node.push_back(n / kSectionNodes);
    }
    if (!spec.fixed.empty()) {
      // select_nodes reads the nodes, their tags (index + 1) and which are on the surface.
      TetMesh nodes;
      nodes.nodes = body.network.rest_positions;
      for (int n = 0; n < body.network.node_count(); ++n) nodes.node_tags.push_back(n + 1);
      BoundarySurface surface;
      surface.nodes = body.network.surface_nodes;
      for (const NodeSelector& selector : spec.fixed)
        for (int node : select_nodes(selector, nodes, surface, false))
          body.network.held[static_cast<std::size_t>(node)] = 1;
    }
    for (const HeatedRegion& region : spec.heated)
      body.heated_springs += heat_springs(body.network, region);
  } catch (const SceneError&) {
    throw;
  } catch (const Error& e) {
    throw SceneError(fmt::format("{}: {}", where, e.what()));
  }
  MassSpringParameters& p = body.network.parameters;
  p.gravity = spec.gravity;
  p.node_damping = spec.node_damping;
  p.tool_friction = spec.tool_friction;
  p.plane = spec.plane;
  body.critical_time_step = critical_time_step(body.network);
  p.time_step = spec.time_step.value_or(kDefaultStepFraction * body.critical_time_step);
  if (p.time_step >= body.critical_time_step)
    throw SceneError(fmt::format(
        "{}: time_step {} s is at or above the network's critical step {:.3g} s (2/omega_max): "
        "the integrator would diverge",
        where, p.time_step, body.critical_time_step));
  check_network(body.network, where.c_str());
  return body;
}

}  // namespace cohaptic
