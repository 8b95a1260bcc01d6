// The several-objects paper's Table 2 on its front object A (scenes/objects/push.yaml: the
// 60-node lattice of springs of 100 N/m, dampers of 0.10 N s/m, nodes of 0.05 kg, its
// bottom held), one displaced node (the pushed one, 1 mm in, A's other nodes at rest):
//   BM_FrontReaction     A's reaction on the displaced node: every spring-damper's force
//                        (internal_forces) and the node's Eq. (5) force (haptic_node_force);
//                        the paper's 0.022 ms
//   BM_FrontDeformation  A's deformation: one integrator step of the whole network with the
//                        node driven (step_network); the paper's 1.615 ms
//   BM_FrontPeriod       what the server does per 1 ms step: the period's 10 integrator steps
//                        with the tool pressing and B's backing on A's back (advance_with_tools)
#include <benchmark/benchmark.h>

#include "common/mass_spring/haptic_node_force.h"
#include "common/mass_spring/integrate_network.h"
#include "common/mass_spring/internal_forces.h"
#include "common/mass_spring/tool_coupling.h"
#include "common/model/scene_compliance.h"
#include "common/scene/load_scene.h"
#include "common/sim/body_interaction.h"
#include "lab/objects_push.h"

namespace cohaptic {
namespace {

struct PaperFront {
  Model model;
  PushLayout layout;
  int node = -1;  // the pushed node
  Eigen::Vector3d target, normal;
  explicit PaperFront(const Scene& scene) : model(build_model(scene)), layout(push_layout(scene)) {
    const Eigen::Vector3d point = push_point(scene, layout);
    const MassSpringNetwork& network = body().network;
    for (int n = 0; n < network.node_count(); ++n)
      if ((network.rest_positions.col(n) - point).norm() < 1e-9) node = n;
    normal = -Eigen::Vector3d::Unit(layout.axis);
    target = point - 1e-3 * normal;
  }
  const MassSpringModel& body() const {
    return std::get<MassSpringModel>(model.bodies[static_cast<std::size_t>(layout.front)]);
  }
};

const Scene& push_scene_file() {
  static const Scene scene =
      load_scene(std::string(COHAPTIC_SOURCE_DIR) + "/scenes/objects/push.yaml");
  return scene;
}

void BM_FrontReaction(benchmark::State& state) {
  const PaperFront front(push_scene_file());
  const MassSpringNetwork& network = front.body().network;
  MassSpringState s = make_state(network);
  s.positions.col(front.node) = front.target;
  const double h = network.parameters.time_step;
  for (auto _ : state) {
    internal_forces(network, s.positions, s.velocities, s.forces);
    const HapticNodeForce reaction = haptic_node_force(
        network.mass[front.node], s.positions.col(front.node), s.velocities.col(front.node),
        s.forces.col(front.node), front.target, front.normal, network.parameters.tool_friction, h);
    benchmark::DoNotOptimize(reaction.force.data());
  }
  state.counters["nodes"] = network.node_count();
  state.counters["springs"] = static_cast<double>(network.springs.size());
}
BENCHMARK(BM_FrontReaction)->Unit(benchmark::kMicrosecond);

void BM_FrontDeformation(benchmark::State& state) {
  const PaperFront front(push_scene_file());
  const MassSpringNetwork& network = front.body().network;
  const MassSpringState rest = make_state(network);
  MassSpringState s = rest;
  const NodeDrive drive{front.node, front.target, front.normal};
  Eigen::Vector3d applied;
  for (auto _ : state) {
    state.PauseTiming();
    s.positions = rest.positions;  // each step from the same state: the node 1 mm from its target
    s.velocities.setZero();
    state.ResumeTiming();
    step_network(network, s, std::span(&drive, 1), std::span(&applied, 1),
                 network.parameters.time_step);
    benchmark::DoNotOptimize(s.positions.data());
  }
  state.counters["nodes"] = network.node_count();
}
BENCHMARK(BM_FrontDeformation)->Unit(benchmark::kMicrosecond);

void BM_FrontPeriod(benchmark::State& state) {
  const PaperFront front(push_scene_file());
  const MassSpringModel& body = front.body();
  const SceneCompliance compliance = prepare_scene_compliance(front.model, true, std::nullopt);
  const auto& behind =
      std::get<ElasticBody>(front.model.bodies[static_cast<std::size_t>(front.layout.behind)]);
  BodyInteraction interaction =
      make_body_interaction(front.layout.front, body, front.layout.behind, behind);
  MassSpringState s = make_state(body.network);
  const NodeBacking backing =
      step_body_interaction(interaction, s.positions, body, behind,
                            *compliance.per_body[static_cast<std::size_t>(front.layout.behind)]);
  const ToolOnNetwork tool{front.target, 0};
  ToolPress press;
  NetworkToolReaction reaction;
  const MassSpringState rest = s;
  for (auto _ : state) {
    state.PauseTiming();
    s = rest;
    press = {};
    state.ResumeTiming();
    advance_with_tools(body.network, s, std::span(&tool, 1), std::span(&press, 1),
                       std::span(&reaction, 1), 1e-3, backing.empty() ? nullptr : &backing);
    benchmark::DoNotOptimize(reaction.force.data());
  }
  state.counters["substeps"] = substeps_for(body.network, 1e-3);
  state.counters["backed_nodes"] = static_cast<double>(backing.nodes.size());
}
BENCHMARK(BM_FrontPeriod)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace cohaptic
