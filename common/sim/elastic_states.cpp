#include "common/sim/elastic_states.h"

namespace cohaptic {

std::vector<std::optional<StateSolution>> solve_elastic_states(SceneSimulation& simulation) {
  std::vector<std::optional<StateSolution>> states(
      static_cast<std::size_t>(simulation.body_count()));
  for (int i = 0; i < simulation.body_count(); ++i)
    if (auto* fem = std::get_if<Simulation>(&simulation.body(i)))
      states[static_cast<std::size_t>(i)] = fem->solve();
  return states;
}

}  // namespace cohaptic
