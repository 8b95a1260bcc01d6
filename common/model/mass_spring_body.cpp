#include "common/model/mass_spring_body.h"

#include <fmt/format.h>

#include "common/mass_spring/stable_time_step.h"
#include "common/scene/load_scene.h"
#include "common/util/error.h"

namespace cohaptic {

MassSpringModel build_mass_spring_body(const std::string& name, const MassSpringObjectSpec& spec, const std::string& where) {
  MassSpringModel body;
  body.name = name;
  body.spec = spec;
  try {
    body.network = tube_network(spec.tube, spec.material);
    for (const HeatedRegion& region : spec.heated) body.heated_springs += heat_springs(body.network, region);
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
    throw SceneError(fmt::format("{}: time_step {} s is at or above the network's critical step {:.3g} s (2/omega_max): "
                                 "the integrator would diverge", where, p.time_step, body.critical_time_step));
  body.section_count = spec.tube.sections;
  body.section_of_node.resize(static_cast<std::size_t>(body.network.node_count()));
  for (int n = 0; n < body.network.node_count(); ++n) body.section_of_node[static_cast<std::size_t>(n)] = n / kSectionNodes;
  check_network(body.network, where.c_str());
  return body;
}

}  // namespace cohaptic
