#include "common/separation/separation_contact.h"

#include <cmath>

#include "common/separation/bracketed_root.h"
#include "common/separation/fracture_step.h"
#include "common/separation/patch_walk.h"

namespace cohaptic {
namespace {

struct Evaluation {
  FieldValue value;
  double normal = 0;                                     ///< F . n
  Eigen::Vector3d tangential = Eigen::Vector3d::Zero();  ///< F - (F . n) n
};

Evaluation evaluate(const SeparationPatch& patch, const SeparationState& state,
                    const SeparationContact& contact, const Eigen::Vector3d& tool) noexcept {
  Evaluation e;
  e.value = contact_field(patch, contact.point, contact_areas(patch, state, contact.point.triangle),
                          contact_deflection(contact, tool));
  const Eigen::Vector3d n = patch.normals[contact.point.triangle];
  e.normal = e.value.force.dot(n);
  e.tangential = e.value.force - e.normal * n;
  return e;
}

SeparationContact moved_to(const SeparationContact& contact, const PatchWalk& walk) noexcept {
  SeparationContact moved = contact;
  moved.point.triangle = walk.triangle;
  moved.point.weights = walk.weights;
  moved.position = walk.point;
  return moved;
}

struct Slide {
  SeparationContact contact;
  PatchWalk walk;
};

// Moves c along the tangential force on the body, d = F_t / |F_t|, until excess(evaluation)
// is down to zero — or, when it stays positive, only as far as the tangential force still
// points along d (or the walk stops first). Moving c by ds along d changes the fields'
// energy by -F_t . d ds plus what the interpolation between nodal fields adds (c moving
// towards stiffer nodes at the same deflection): the slip is cut short where the energy
// would rise above its value before it, so that a slip never feeds the hand.
template <typename Excess>
Slide slide_until(const SeparationPatch& patch, const SeparationState& state,
                  const SeparationContact& contact, const Eigen::Vector3d& tool,
                  bool stop_at_crack_edges, const Excess& excess) noexcept {
  Slide slide{contact, PatchWalk{}};
  slide.walk.triangle = contact.point.triangle;
  slide.walk.weights = contact.point.weights;
  slide.walk.point = contact.position;
  const Evaluation start = evaluate(patch, state, contact, tool);
  const double start_excess = excess(start);
  const double tangential = start.tangential.norm();
  if (!(tangential > 0) || !(start_excess > 0)) return slide;
  const Eigen::Vector3d direction = start.tangential / tangential;
  const auto walk = [&](double distance) {
    return walk_on_patch(patch, state, contact.point.triangle, contact.point.weights, direction,
                         distance, stop_at_crack_edges);
  };
  const auto along_at = [&](const PatchWalk& w) {
    return evaluate(patch, state, moved_to(contact, w), tool).tangential.dot(direction);
  };
  const auto excess_at = [&](const PatchWalk& w) {
    return excess(evaluate(patch, state, moved_to(contact, w), tool));
  };
  // How far F_t . d stays positive: from the deflection's own length, doubled a few times.
  const Eigen::Vector3d n = patch.normals[contact.point.triangle];
  const Eigen::Vector3d delta = contact_deflection(contact, tool);
  double distance = std::max((delta - delta.dot(n) * n).norm(), 1e-9);
  PatchWalk end = walk(distance);
  for (int doubling = 0; doubling < 8 && end.stop == PatchWalk::Stop::none && along_at(end) > 0;
       ++doubling)
    end = walk(distance *= 2);
  double along_end = along_at(end);
  if (along_end < 0) {
    end = walk(bracketed_root([&](double s) { return along_at(walk(s)); }, 0.0, end.travelled,
                              tangential, along_end, 1e-12 * tangential));
  }
  const double end_excess = excess_at(end);
  double length = end.travelled;
  if (end_excess < 0)
    length = bracketed_root([&](double s) { return excess_at(walk(s)); }, 0.0, end.travelled,
                            start_excess, end_excess, 1e-12 * start_excess);
  // The energy guard: the last of 16 even steps up to `length` whose energy is no higher
  // than at the start, then the crossing between it and the next step.
  const auto energy_rise = [&](double s) {
    return evaluate(patch, state, moved_to(contact, walk(s)), tool).value.energy -
           start.value.energy;
  };
  constexpr int kSteps = 16;
  double allowed = 0;
  for (int i = 1; i <= kSteps; ++i) {
    const double s = length * i / kSteps;
    const double rise = energy_rise(s);
    if (rise > 0) {
      allowed = bracketed_root(energy_rise, allowed, s, energy_rise(allowed), rise,
                               1e-12 * std::abs(start.value.energy));
      if (energy_rise(allowed) > 0) allowed = length * (i - 1) / kSteps;
      break;
    }
    allowed = s;
  }
  slide.walk = allowed < end.travelled ? walk(allowed) : end;  // `end` knows where it stopped
  slide.contact = moved_to(contact, slide.walk);
  return slide;
}

}  // namespace

SeparationContact begin_contact(const SeparationPatch& patch, ContactMode mode,
                                const ContactPoint& point, const Eigen::Vector3d& tool) noexcept {
  SeparationContact contact;
  if (point.triangle < 0 || point.triangle >= patch.triangle_count() || !tool.allFinite())
    return contact;
  for (int j : point.tool_nodes)
    if (j < 0 || j >= patch.tool_node_count) return contact;
  const auto valid_weights = [](const Eigen::Vector3d& w) {
    return w.allFinite() && (w.array() >= 0).all() && std::abs(w.sum() - 1) < 1e-9;
  };
  if (!valid_weights(point.weights) || !valid_weights(point.tool_weights)) return contact;
  const Triangle& tri = patch.triangles[point.triangle];
  contact.mode = mode;
  contact.point = point;
  contact.position = point.weights[0] * patch.positions.col(tri[0]) +
                     point.weights[1] * patch.positions.col(tri[1]) +
                     point.weights[2] * patch.positions.col(tri[2]);
  contact.tool_offset = tool - contact.position;
  contact.last_tool = tool;
  return contact;
}

SeparationSample step_contact(const SeparationPatch& patch, SeparationState& state,
                              SeparationContact& contact, const Eigen::Vector3d& tool) noexcept {
  SeparationSample sample;
  if (contact.mode == ContactMode::none) return sample;
  if (!tool.allFinite()) {
    sample.flags |= kSeparationInContact | kSeparationNonFinite;
    return sample;
  }
  sample.flags |= kSeparationInContact;

  const FractureStep fracture = fracture_step(patch, state, contact.point, contact.position,
                                              contact_deflection(contact, contact.last_tool),
                                              contact_deflection(contact, tool));
  if (fracture.separated > 0) sample.flags |= kSeparationFracture;
  sample.separated = fracture.separated;
  sample.fracture_motion = fracture.fracture_motion;
  if (fracture.in_reach && !fracture.held) {
    // The contact's region is used up: pushed along the interface, c moves on with the
    // crack edge at the threshold (Fig. 3); pulled straight away, the force rises.
    const Eigen::Vector3d n = patch.normals[contact.point.triangle];
    const Slide slide = slide_until(patch, state, contact, tool, false, [&](const Evaluation& at) {
      return opening_force(at.value.force, n, fracture.direction) - fracture.threshold;
    });
    contact = slide.contact;
    if (slide.walk.travelled > 0) sample.flags |= kSeparationSliding;
    if (opening_force(evaluate(patch, state, contact, tool).value.force, n, fracture.direction) >
        fracture.threshold * (1 + 1e-9))
      sample.flags |= kSeparationAboveThreshold;
  }

  Evaluation e = evaluate(patch, state, contact, tool);
  if (contact.mode == ContactMode::push && e.normal < 0) {
    contact.mode = ContactMode::none;
    sample.flags =
        static_cast<std::uint16_t>((sample.flags & ~kSeparationInContact) | kSeparationReleased);
    return sample;
  }
  if (contact.mode == ContactMode::push && e.tangential.norm() > patch.friction * e.normal) {
    const Slide slide = slide_until(patch, state, contact, tool, true, [&](const Evaluation& at) {
      return at.tangential.norm() - patch.friction * at.normal;
    });
    contact = slide.contact;
    if (slide.walk.travelled > 0) sample.flags |= kSeparationSliding;
    if (slide.walk.stop == PatchWalk::Stop::crack_edge)
      sample.flags |= kSeparationStoppedAtCrackEdge;
  }

  e = evaluate(patch, state, contact, tool);
  sample.body_force = e.value.force;
  sample.energy = e.value.energy;
  sample.deflection = contact_deflection(contact, tool);
  contact.last_tool = tool;
  if (!sample.body_force.allFinite()) {
    sample.flags |= kSeparationNonFinite;
    return sample;
  }
  sample.force = -sample.body_force;
  const double magnitude = sample.force.norm();
  if (magnitude > patch.force_limit) {
    sample.force *= patch.force_limit / magnitude;
    sample.flags |= kSeparationClamped;
  }
  return sample;
}

}  // namespace cohaptic
