#include "common/separation/pull_loop.h"

#include <cmath>
#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {

ContactPoint contact_at_node(const SeparationPatch& patch, int node) {
  if (node < 0 || node >= patch.node_count())
    throw Error(fmt::format("separation: node {} is not on the patch ({} nodes)", node, patch.node_count()));
  ContactPoint point;
  point.triangle = patch.regions.of(node).front();
  for (int k = 0; k < 3; ++k) point.weights[k] = patch.triangles[point.triangle][k] == node ? 1.0 : 0.0;
  return point;
}

PullLoop run_pull_loop(const SeparationPatch& patch, const SeparationState& initial, const PullLoopSettings& settings) {
  if (!(settings.speed > 0) || !(settings.tick > 0) || !(settings.max_travel > 0))
    throw Error(fmt::format("pull loop: speed, tick and max_travel must be positive, got {}, {}, {}", settings.speed,
                            settings.tick, settings.max_travel));
  const ContactPoint point = contact_at_node(patch, settings.node);
  const Eigen::Vector3d direction =
      settings.direction.norm() > 0 ? settings.direction.normalized() : region_normal(patch.positions, patch.triangles, patch.regions.of(settings.node));
  const Eigen::Vector3d start = patch.positions.col(settings.node);
  const Eigen::Vector3d normal = patch.normals[point.triangle];

  SeparationState state = initial;
  SeparationContact contact = begin_contact(patch, settings.mode, point, start);
  PullLoop loop;
  loop.threshold = patch.normal_threshold;
  const double step = settings.speed * settings.tick;
  const int max_steps = static_cast<int>(std::ceil(settings.max_travel / step));

  PullLoopSample sample;
  sample.local_separated = local_separated_share(patch, state, settings.node);
  sample.separated_area = state.separated_area;
  loop.samples.push_back(sample);
  double travel = 0;
  bool turned = false;
  int quiet_fracture_ticks = 0;
  for (int i = 1; i <= 2 * max_steps + 1; ++i) {
    const double previous_travel = travel;
    travel = turned ? std::max(travel - step, 0.0) : std::min(travel + step, settings.max_travel);
    const SeparationSample s = step_contact(patch, state, contact, start + travel * direction);
    PullLoopSample next;
    next.time = i * settings.tick;
    next.travel = travel;
    next.force = s.body_force.dot(direction);
    next.normal_force = s.body_force.dot(normal);
    next.separated_area = state.separated_area;
    next.local_separated = local_separated_share(patch, state, settings.node);
    const PullLoopSample& last = loop.samples.back();
    const bool fractured = s.separated > 0;
    next.phase = turned ? PullPhase::unloading
                        : (fractured || last.phase == PullPhase::fracture ? PullPhase::fracture : PullPhase::loading);
    const double work = 0.5 * (last.force + next.force) * (travel - previous_travel);
    loop.net_work += work;
    if (next.phase == PullPhase::fracture) {
      loop.fracture_work += work;
      loop.fracture_area += s.separated;
      loop.fracture_travel += (travel - previous_travel) * direction.dot(normal);
    }
    loop.samples.push_back(next);
    if (turned && travel <= 0) break;
    if (!turned) {
      quiet_fracture_ticks = next.phase == PullPhase::fracture && !fractured ? quiet_fracture_ticks + 1 : 0;
      if (next.local_separated >= 1 - 1e-12 || quiet_fracture_ticks >= 10 || travel >= settings.max_travel) {
        turned = true;
        loop.turn_travel = travel;
      }
    }
  }
  return loop;
}

}  // namespace cohaptic
