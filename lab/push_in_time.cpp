#include "lab/push_in_time.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "common/mass_spring/network_equilibrium.h"
#include "common/model/scene_compliance.h"
#include "common/sim/scene_simulation.h"
#include "common/util/error.h"

namespace cohaptic {

std::vector<PushInTimeSample> push_in_time(const Scene& scene, const PushVariation& variation,
                                           const PushInTimeOptions& options) {
  const PushLayout layout = push_layout(scene);
  if (scene.tools.empty()) throw Error("push in time: the scene has no tool");
  const Model model = build_model(push_scene(scene, variation));
  const SceneCompliance compliance = prepare_scene_compliance(model, true, std::nullopt);
  SceneSimulation simulation(model, compliance.per_body, model.scene.tools, SimulationOptions{});
  const Eigen::Vector3d start = push_point(scene, layout);
  const Eigen::Vector3d axis = Eigen::Vector3d::Unit(layout.axis);
  const double period = 1 / scene.haptic.rate_hz;
  // Until the last period's mean depth reaches the push's end.
  const auto steps =
      static_cast<int>(std::ceil(options.depth / options.speed / period + 0.5 - 1e-9));

  std::vector<PushInTimeSample> samples;
  for (int i = 0; i <= steps; ++i) {
    const double time = i * period;
    simulation.set_tool(0, start + options.speed * time * axis);
    simulation.step(time);
    if (i == 0) continue;
    if (simulation.body_of(0) != layout.front)
      throw Error(fmt::format("push in time: at {} s the tool is on object {}, not A", time,
                              simulation.body_of(0)));
    const auto& front = std::get<MassSpringSimulation>(simulation.body(layout.front));
    if (!front.reaction(0).colliding)
      throw Error(fmt::format("push in time: at {} s the tool does not press A", time));
    // The node went from the tool's previous position to its present one over the period.
    samples.push_back(
        {time, options.speed * (time - period / 2), -front.reaction(0).force.dot(axis)});
  }
  return samples;
}

std::vector<double> network_static_forces(const Scene& scene, const PushVariation& variation,
                                          const std::vector<double>& depths) {
  if (variation.condition == BackCondition::on_behind)
    throw Error(
        "network_static_forces: A's network alone has no body behind it (conditions free and fixed "
        "only)");
  const PushLayout layout = push_layout(scene);
  const Model model = build_model(push_scene(scene, variation));
  const MassSpringNetwork& network =
      std::get<MassSpringModel>(model.bodies[static_cast<std::size_t>(layout.front)]).network;
  const Eigen::Vector3d point = push_point(scene, layout);
  int node = 0;
  for (int n = 1; n < network.node_count(); ++n)
    if ((network.rest_positions.col(n) - point).norm() <
        (network.rest_positions.col(node) - point).norm())
      node = n;
  std::vector<double> forces;
  Eigen::Matrix3Xd positions = network.rest_positions;
  for (double depth : depths) {
    std::array<PrescribedDisplacement, 3> held;
    for (int axis = 0; axis < 3; ++axis)
      held[static_cast<std::size_t>(axis)] = {3 * node + axis, axis == layout.axis ? depth : 0.0};
    const NetworkEquilibrium equilibrium = network_equilibrium(network, held, positions);
    positions = equilibrium.positions;
    forces.push_back(equilibrium.reaction[3 * node + layout.axis]);
  }
  return forces;
}

std::vector<double> forces_at_depths(const std::vector<PushInTimeSample>& samples,
                                     const std::vector<double>& depths) {
  std::vector<double> forces;
  for (double depth : depths) {
    const auto after = std::find_if(samples.begin(), samples.end(),
                                    [&](const PushInTimeSample& s) { return s.depth >= depth; });
    if (after == samples.end() || after == samples.begin())
      throw Error(fmt::format("push in time: the samples do not reach around depth {} m", depth));
    const PushInTimeSample& before = *(after - 1);
    const double t = (depth - before.depth) / (after->depth - before.depth);
    forces.push_back(before.force + t * (after->force - before.force));
  }
  return forces;
}

}  // namespace cohaptic
