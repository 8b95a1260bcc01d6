#include "common/separation/pull_loop.h"

#include <cmath>
#include <fmt/format.h>

#include "common/separation/bracketed_root.h"
#include "common/separation/fracture_step.h"
#include "common/util/error.h"

namespace cohaptic {

ContactPoint contact_at_node(const SeparationPatch& patch, int node) {
  if (node < 0 || node >= patch.node_count())
    throw Error(fmt::format("separation: node {} is not on the patch ({} nodes)", node,
                            patch.node_count()));
  ContactPoint point;
  point.triangle = patch.regions.of(node).front();
  for (int k = 0; k < 3; ++k)
    point.weights[k] = patch.triangles[point.triangle][k] == node ? 1.0 : 0.0;
  return point;
}

PullLoop run_pull_loop(const SeparationPatch& patch, const SeparationState& initial,
                       const PullLoopSettings& settings) {
  if (!(settings.speed > 0) || !(settings.tick > 0) || !(settings.max_travel > 0))
    throw Error(
        fmt::format("pull loop: speed, tick and max_travel must be positive, got {}, {}, {}",
                    settings.speed, settings.tick, settings.max_travel));
  const ContactPoint point = contact_at_node(patch, settings.node);
  const Eigen::Vector3d direction =
      settings.direction.norm() > 0
          ? settings.direction.normalized()
          : region_normal(patch.positions, patch.triangles, patch.regions.of(settings.node));
  const Eigen::Vector3d start = patch.positions.col(settings.node);
  const Eigen::Vector3d normal = patch.normals[point.triangle];

  SeparationState state = initial;
  SeparationContact contact = begin_contact(patch, settings.mode, point, start);
  PullLoop loop;
  loop.threshold = patch.toughness * opening_length(patch, normal, direction);
  const double step = settings.speed * settings.tick;
  const int max_steps = static_cast<int>(std::ceil(settings.max_travel / step));

  // Appends a sample; the work of the segment that ends at it counts in its phase.
  const auto append = [&](PullLoopSample next, double separated, const SeparationState& shares) {
    if (!loop.samples.empty()) {
      const PullLoopSample& last = loop.samples.back();
      const double work = 0.5 * (last.force + next.force) * (next.travel - last.travel);
      loop.net_work += work;
      if (next.phase == PullPhase::fracture) {
        loop.fracture_work += work;
        loop.fracture_area += separated;
        loop.fracture_travel += (next.travel - last.travel) * direction.dot(normal);
      }
    }
    next.separated_area = shares.separated_area;
    next.local_separated = local_separated_share(patch, shares, settings.node);
    loop.samples.push_back(next);
  };
  const auto sample_at = [&](double time, double travel, const Eigen::Vector3d& force,
                             PullPhase phase) {
    PullLoopSample s;
    s.time = time;
    s.travel = travel;
    s.force = force.dot(direction);
    s.normal_force = force.dot(normal);
    s.phase = phase;
    return s;
  };
  append(sample_at(0, 0, Eigen::Vector3d::Zero(), PullPhase::loading), 0, state);

  // C: the contact's region is used up, or fracture can no longer hold the force.
  const auto at_c = [&](const SeparationSample& s) {
    return local_separated_share(patch, state, settings.node) >= 1 - 1e-12 ||
           (s.flags & kSeparationAboveThreshold) != 0;
  };
  double travel = 0;
  bool turned = false, fracturing = false;
  int quiet_fracture_ticks = 0;
  for (int i = 1; i <= 2 * max_steps + 1; ++i) {
    const double previous_travel = travel;
    travel = turned ? std::max(travel - step, 0.0) : std::min(travel + step, settings.max_travel);
    const SeparationState state_before = state;
    const SeparationContact contact_before = contact;
    SeparationSample s = step_contact(patch, state, contact, start + travel * direction);
    const bool fractured = s.separated > 0;
    if (!turned && fractured && !fracturing) {
      // Point B: where, on this tick's way, the force first met a threshold. Inserted so
      // that the work over BC starts exactly there, whatever the tick's length.
      const auto force_at = [&](double tau) {
        return contact_field(patch, contact_before.point,
                             contact_areas(patch, state_before, contact_before.point.triangle),
                             contact_deflection(contact_before,
                                                start + (previous_travel + tau * step) * direction))
            .force;
      };
      const auto excess = [&](double tau) {
        return opening_force(force_at(tau), normal, direction) - loop.threshold;
      };
      const double tau =
          bracketed_root(excess, 0.0, 1.0, excess(0.0), excess(1.0), 1e-12 * loop.threshold);
      append(sample_at((i - 1 + tau) * settings.tick, previous_travel + tau * step, force_at(tau),
                       PullPhase::loading),
             0, state_before);
    } else if (!turned && fracturing && at_c(s)) {
      // Point C falls inside this tick: redo it in sub-ticks and turn at the first that
      // reaches C, so that BC does not end with most of a tick of loading past C.
      constexpr int kSubticks = 32;
      state = state_before;
      contact = contact_before;
      for (int k = 1; k <= kSubticks; ++k) {
        travel = previous_travel + step * k / kSubticks;
        s = step_contact(patch, state, contact, start + travel * direction);
        if (k == kSubticks || at_c(s)) break;
        append(sample_at((i - 1 + double(k) / kSubticks) * settings.tick, travel, s.body_force,
                         PullPhase::fracture),
               s.separated, state);
      }
    }
    fracturing = fracturing || s.separated > 0;
    const PullPhase phase = turned       ? PullPhase::unloading
                            : fracturing ? PullPhase::fracture
                                         : PullPhase::loading;
    const double time =
        loop.samples.back().time + std::abs(travel - loop.samples.back().travel) / settings.speed;
    append(sample_at(time, travel, s.body_force, phase), s.separated, state);
    loop.final_energy = s.energy;
    if (turned && travel <= 0) break;
    if (!turned) {
      quiet_fracture_ticks = fracturing && s.separated == 0 ? quiet_fracture_ticks + 1 : 0;
      if ((fracturing && at_c(s)) || quiet_fracture_ticks >= 10 || travel >= settings.max_travel) {
        turned = true;
        loop.turn_travel = travel;
      }
    }
  }
  return loop;
}

}  // namespace cohaptic
