#include "common/separation/separation_contact.h"

#include <cmath>
#include <limits>

#include "common/separation/bracketed_root.h"
#include "common/separation/crack_growth.h"
#include "common/separation/normal_fracture.h"
#include "common/separation/patch_walk.h"

namespace cohaptic {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct Evaluation {
  FieldValue value;
  double normal = 0;                                     ///< F . n
  Eigen::Vector3d tangential = Eigen::Vector3d::Zero();  ///< F - (F . n) n
};

Evaluation evaluate(const SeparationPatch& patch, const SeparationState& state, const SeparationContact& contact,
                    const Eigen::Vector3d& tool) noexcept {
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

// Moves c along the tangential deflection until the tangential force is down to `limit`
// (or as far as the walk goes, when it stops first with the force still above).
Slide slide_to_limit(const SeparationPatch& patch, const SeparationState& state, const SeparationContact& contact,
                     const Eigen::Vector3d& tool, double limit, bool stop_at_crack_edges) noexcept {
  const Eigen::Vector3d n = patch.normals[contact.point.triangle];
  const Eigen::Vector3d delta = contact_deflection(contact, tool);
  const Eigen::Vector3d tangential = delta - delta.dot(n) * n;
  const double reach = tangential.norm();
  Slide slide{contact, PatchWalk{}};
  slide.walk.triangle = contact.point.triangle;
  slide.walk.weights = contact.point.weights;
  slide.walk.point = contact.position;
  if (!(reach > 0)) return slide;
  const Eigen::Vector3d direction = tangential / reach;
  const auto walk = [&](double distance) {
    return walk_on_patch(patch, state, contact.point.triangle, contact.point.weights, direction, distance,
                         stop_at_crack_edges);
  };
  const auto excess_at = [&](const PatchWalk& w) {
    return evaluate(patch, state, moved_to(contact, w), tool).tangential.norm() - limit;
  };
  const PatchWalk full = walk(reach);
  const double full_excess = excess_at(full);
  if (full_excess >= 0) {
    slide.walk = full;
  } else {
    const double start_excess = evaluate(patch, state, contact, tool).tangential.norm() - limit;
    const double distance = bracketed_root([&](double s) { return excess_at(walk(s)); }, 0.0, full.travelled,
                                           start_excess, full_excess, 1e-12 * std::max(limit, 1e-9));
    slide.walk = walk(distance);
  }
  slide.contact = moved_to(contact, slide.walk);
  return slide;
}

bool crack_front_in_reach(const SeparationPatch& patch, const SeparationState& state, const ContactPoint& point) noexcept {
  const ContactRegion region = contact_region(patch, point);
  for (int i = 0; i < region.count; ++i)
    if (can_grow(patch, state, region.triangles[i])) return true;
  return false;
}

// Pushed at the tangential threshold: c moves with the crack edge, l_t per metre separates.
void tangential_fracture(const SeparationPatch& patch, SeparationState& state, SeparationContact& contact,
                         const Eigen::Vector3d& tool, SeparationSample& sample) noexcept {
  const Slide slide = slide_to_limit(patch, state, contact, tool, patch.tangential_threshold, false);
  contact = slide.contact;
  const double separated =
      grow_nearest(patch, state, contact.position, patch.tangential_length * slide.walk.travelled, nullptr);
  if (separated > 0) sample.flags |= kSeparationTangentialFracture;
  sample.separated += separated;
  sample.fracture_motion += separated / patch.tangential_length;
}

}  // namespace

SeparationContact begin_contact(const SeparationPatch& patch, ContactMode mode, const ContactPoint& point,
                                const Eigen::Vector3d& tool) noexcept {
  SeparationContact contact;
  if (point.triangle < 0 || point.triangle >= patch.triangle_count() || !tool.allFinite()) return contact;
  for (int j : point.tool_nodes)
    if (j < 0 || j >= patch.tool_node_count) return contact;
  const auto valid_weights = [](const Eigen::Vector3d& w) {
    return w.allFinite() && (w.array() >= 0).all() && std::abs(w.sum() - 1) < 1e-9;
  };
  if (!valid_weights(point.weights) || !valid_weights(point.tool_weights)) return contact;
  const Triangle& tri = patch.triangles[point.triangle];
  contact.mode = mode;
  contact.point = point;
  contact.position = point.weights[0] * patch.positions.col(tri[0]) + point.weights[1] * patch.positions.col(tri[1]) +
                     point.weights[2] * patch.positions.col(tri[2]);
  contact.tool_offset = tool - contact.position;
  contact.last_tool = tool;
  return contact;
}

SeparationSample step_contact(const SeparationPatch& patch, SeparationState& state, SeparationContact& contact,
                              const Eigen::Vector3d& tool) noexcept {
  SeparationSample sample;
  if (contact.mode == ContactMode::none) return sample;
  if (!tool.allFinite()) {
    sample.flags |= kSeparationInContact | kSeparationNonFinite;
    return sample;
  }
  sample.flags |= kSeparationInContact;

  const NormalFracture normal = normal_fracture(patch, state, contact.point, contact.position,
                                                contact_deflection(contact, contact.last_tool),
                                                contact_deflection(contact, tool));
  if (normal.separated > 0) sample.flags |= kSeparationNormalFracture;
  if (!normal.held) sample.flags |= kSeparationAboveThreshold;
  sample.separated += normal.separated;
  sample.fracture_motion += normal.fracture_motion;

  Evaluation e = evaluate(patch, state, contact, tool);
  if (contact.mode == ContactMode::push && e.normal < 0) {
    contact.mode = ContactMode::none;
    sample.flags = static_cast<std::uint16_t>((sample.flags & ~kSeparationInContact) | kSeparationReleased);
    return sample;
  }
  const double friction_limit = contact.mode == ContactMode::push ? patch.friction * e.normal : kInfinity;
  const double tangential = e.tangential.norm();
  if (tangential > friction_limit || tangential > patch.tangential_threshold) {
    const double fracture_limit =
        crack_front_in_reach(patch, state, contact.point) ? patch.tangential_threshold : kInfinity;
    if (tangential > std::min(friction_limit, fracture_limit)) {
      if (friction_limit < fracture_limit) {
        const Slide slide = slide_to_limit(patch, state, contact, tool, friction_limit, true);
        contact = slide.contact;
        if (slide.walk.travelled > 0) sample.flags |= kSeparationSliding;
        if (slide.walk.stop == PatchWalk::Stop::crack_edge) {
          sample.flags |= kSeparationStoppedAtCrackEdge;
          if (evaluate(patch, state, contact, tool).tangential.norm() > patch.tangential_threshold &&
              crack_front_in_reach(patch, state, contact.point))
            tangential_fracture(patch, state, contact, tool, sample);
        }
      } else {
        tangential_fracture(patch, state, contact, tool, sample);
      }
    }
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
