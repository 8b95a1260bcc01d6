#include "lab/tradeoff_home_spring.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <memory>

#include "common/ir/evaluate_force.h"
#include "common/model/model.h"
#include "common/sim/home_spring_simulation.h"
#include "common/util/error.h"
#include "common/util/percentile.h"
#include "common/util/stopwatch.h"

namespace cohaptic {
namespace {

double tissue_memory_mb(const HomeSpringBody& body) {
  const double vertices = static_cast<double>(body.surface.vertex_count()) * 3 * sizeof(double);
  const double triangles = static_cast<double>(body.surface.triangle_count()) * 3 * sizeof(int);
  const double rings = static_cast<double>(body.rings.offsets.size() + body.rings.vertices.size()) * sizeof(int);
  return (vertices + triangles + rings) / 1e6;
}

}  // namespace

TradeoffRow run_home_spring_setting(const Scene& scene, const std::vector<Trajectory>& motions,
                                    const ReferenceTrace& reference, int per_step, int per_tick) {
  if (scene.objects.size() != 1 || !std::holds_alternative<HomeSpringObjectSpec>(scene.objects.front().body))
    throw Error(fmt::format("{}: the home-spring trade-off needs a scene of one home_spring object", scene.file.string()));
  const std::size_t users = scene.tools.size();
  if (motions.size() != users || reference.positions.empty() || reference.positions.front().size() != users)
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

  constexpr double kUnlimited = std::numeric_limits<double>::infinity();  // compare the physics, not the limiter
  HomeSpringSimulation server(body, 0, scene.tools, kUnlimited);
  HomeSpringSimulation every_sample(body, 0, scene.tools, kUnlimited);
  std::vector<std::shared_ptr<const PreparedIR>> published(users);
  std::vector<Eigen::Vector3d> held(users, Eigen::Vector3d::Zero());
  std::vector<double> rebuild_ms, plain_step_ms, evaluation_us;
  double rebuild_step_ms = 0, bytes = 0, sum_squared = 0, worst = 0, own_sum_squared = 0, own_worst = 0;
  const std::size_t samples = reference.positions.size();
  for (std::size_t j = 0; j < samples; ++j) {
    const double t = static_cast<double>(j) / reference.sample_rate_hz;
    const std::vector<Eigen::Vector3d>& positions = reference.positions[j];
    if (j % static_cast<std::size_t>(per_step) == 0) {
      for (std::size_t u = 0; u < users; ++u) server.set_tool(static_cast<int>(u), positions[u]);
      const Stopwatch step;
      const StepReport report = server.step(t);
      const double ms = step.elapsed_ms();
      if (report.rebuilt) {
        rebuild_ms.push_back(report.rebuild_ms);
        rebuild_step_ms += ms;
      } else {
        plain_step_ms.push_back(ms);
      }
      for (std::size_t u = 0; u < users; ++u)
        if (const auto ir = server.ir(static_cast<int>(u)); ir && ir != published[u]) {
          published[u] = ir;
          bytes += static_cast<double>(ir->ir.size_bytes());
          ++row.irs_sent;
        }
    }
    if (j % static_cast<std::size_t>(per_tick) == 0)
      for (std::size_t u = 0; u < users; ++u) {
        if (!published[u]) continue;
        const Stopwatch evaluation;
        EvaluationState stateless;  // the home-spring body keeps none and ignores dt
        held[u] = evaluate_force(*published[u], stateless, positions[u], {}, 0).force;
        evaluation_us.push_back(1000 * evaluation.elapsed_ms());
      }
    for (std::size_t u = 0; u < users; ++u) every_sample.set_tool(static_cast<int>(u), positions[u]);
    every_sample.step(t);
    for (std::size_t u = 0; u < users; ++u) {
      const double error = (held[u] - reference.forces[j][u]).norm();
      sum_squared += error * error;
      worst = std::max(worst, error);
      const double own_error = (held[u] - every_sample.force(static_cast<int>(u)).force).norm();
      own_sum_squared += own_error * own_error;
      own_worst = std::max(own_worst, own_error);
    }
  }
  const double duration = static_cast<double>(samples) / reference.sample_rate_hz;
  const double peak = std::max(reference.peak_force, 1e-300);
  row.error_rms = std::sqrt(sum_squared / static_cast<double>(samples * users)) / peak;
  row.error_max = worst / peak;
  row.own_mesh_error_rms = std::sqrt(own_sum_squared / static_cast<double>(samples * users)) / peak;
  row.own_mesh_error_max = own_worst / peak;
  row.mtilde_ms_p50 = rebuild_ms.empty() ? 0 : percentile(rebuild_ms, 0.5);
  row.mtilde_ms_p99 = rebuild_ms.empty() ? 0 : percentile(rebuild_ms, 0.99);
  row.evaluation_us = evaluation_us.empty() ? 0 : percentile(evaluation_us, 0.5);
  row.ir_bytes_per_s = bytes / duration;
  const double plain_steps_ms =
      plain_step_ms.empty() ? 0 : percentile(plain_step_ms, 0.5) * static_cast<double>(plain_step_ms.size());
  const double evaluations_ms = row.evaluation_us * static_cast<double>(evaluation_us.size()) / 1000;
  row.cpu_ms_per_s = (rebuild_step_ms + plain_steps_ms + evaluations_ms) / duration;
  return row;
}

}  // namespace cohaptic
