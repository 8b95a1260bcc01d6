#include "lab/tradeoff_home_spring.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <memory>

#include "common/ir/evaluate_force.h"
#include "common/model/model.h"
#include "common/sim/home_spring_simulation.h"
#include "common/util/error.h"
#include "common/util/stopwatch.h"
#include "lab/tradeoff_tally.h"

namespace cohaptic {
namespace {

double tissue_memory_mb(const HomeSpringBody& body) {
  const double vertices = static_cast<double>(body.surface.vertex_count()) * 3 * sizeof(double);
  const double triangles = static_cast<double>(body.surface.triangle_count()) * 3 * sizeof(int);
  const double rings =
      static_cast<double>(body.rings.offsets.size() + body.rings.vertices.size()) * sizeof(int);
  return (vertices + triangles + rings) / 1e6;
}

}  // namespace

TradeoffRow run_home_spring_setting(const Scene& scene, const std::vector<Trajectory>& motions,
                                    const ReferenceTrace& reference, int per_step, int per_tick) {
  if (scene.objects.size() != 1 ||
      !std::holds_alternative<HomeSpringObjectSpec>(scene.objects.front().body))
    throw Error(fmt::format("{}: the home-spring trade-off needs a scene of one home_spring object",
                            scene.file.string()));
  const std::size_t users = scene.tools.size();
  if (motions.size() != users || reference.positions.empty() ||
      reference.positions.front().size() != users)
    throw Error("tradeoff: the reference, the motions and the scene's tools do not match");
  TradeoffRow row;
  row.setting.knob = "model";
  row.setting.value = "home_spring";
  row.setting.haptic_rate_hz = scene.haptic.rate_hz;

  const Stopwatch precompute;
  const Model model = build_model(scene);
  const HomeSpringBody& body = std::get<HomeSpringBody>(model.bodies.front());
  row.precompute_s = precompute.elapsed_ms() / 1000;
  row.nodes = body.surface.vertex_count();
  row.memory_mb = tissue_memory_mb(body);

  constexpr double kUnlimited =
      std::numeric_limits<double>::infinity();  // compare the physics, not the limiter
  HomeSpringSimulation server(body, 0, scene.tools, kUnlimited);
  HomeSpringSimulation every_sample(body, 0, scene.tools, kUnlimited);
  std::vector<std::shared_ptr<const PreparedIR>> published(users);
  std::vector<EvaluationState> client(users);  // a viscous tissue's vertex moves in it
  std::vector<EvaluationCarry> carry(users);
  const double tick_s = per_tick / reference.sample_rate_hz;
  std::vector<Eigen::Vector3d> held(users, Eigen::Vector3d::Zero());
  TradeoffTally tally;
  const std::size_t samples = reference.positions.size();
  for (std::size_t j = 0; j < samples; ++j) {
    const double t = static_cast<double>(j) / reference.sample_rate_hz;
    const std::vector<Eigen::Vector3d>& positions = reference.positions[j];
    if (j % static_cast<std::size_t>(per_step) == 0) {
      for (std::size_t u = 0; u < users; ++u) server.set_tool(static_cast<int>(u), positions[u]);
      const Stopwatch step;
      const StepReport report = server.step(t);
      tally.step(report, step.elapsed_ms());
      for (std::size_t u = 0; u < users; ++u)
        if (const auto ir = server.ir(static_cast<int>(u)); ir && ir != published[u]) {
          published[u] = ir;
          client[u] = make_evaluation_state(*ir);
          tally.published(ir->ir.size_bytes());
        }
    }
    if (j % static_cast<std::size_t>(per_tick) == 0)
      for (std::size_t u = 0; u < users; ++u) {
        if (!published[u]) continue;
        const Stopwatch evaluation;
        held[u] =
            evaluate_force_in_turn(*published[u], client[u], carry[u], positions[u], {}, tick_s)
                .force;
        tally.evaluation(1000 * evaluation.elapsed_ms());
      }
    for (std::size_t u = 0; u < users; ++u)
      every_sample.set_tool(static_cast<int>(u), positions[u]);
    every_sample.step(t);
    for (std::size_t u = 0; u < users; ++u)
      tally.sample(held[u], reference.forces[j][u], every_sample.force(static_cast<int>(u)).force);
  }
  tally.finish(row, reference, users);
  return row;
}

}  // namespace cohaptic
