#include "common/separation/fracture_step.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/separation/bracketed_root.h"
#include "common/separation/crack_growth.h"
#include "common/separation/interface_regions.h"

namespace cohaptic {

double opening_length(const SeparationPatch& patch, const Eigen::Vector3d& n,
                      const Eigen::Vector3d& v) noexcept {
  const double along_normal = v.dot(n);
  return patch.normal_length * std::max(0.0, along_normal) +
         patch.tangential_length * (v - along_normal * n).norm();
}

double opening_force(const Eigen::Vector3d& force, const Eigen::Vector3d& n,
                     const Eigen::Vector3d& v) noexcept {
  const double normal_force = force.dot(n), along_normal = v.dot(n);
  return std::max(0.0, normal_force) * std::max(0.0, along_normal) +
         (force - normal_force * n).dot(v - along_normal * n);
}

FractureStep fracture_step(const SeparationPatch& patch, SeparationState& state,
                           const ContactPoint& contact, const Eigen::Vector3d& contact_position,
                           const Eigen::Vector3d& delta_old,
                           const Eigen::Vector3d& delta_new) noexcept {
  FractureStep result;
  const Eigen::Vector3d move = delta_new - delta_old;
  const double motion = move.norm();
  if (!(motion > 0)) return result;
  const Eigen::Vector3d n = patch.normals[contact.triangle];
  const Eigen::Vector3d v = move / motion;
  const double crack_length = opening_length(patch, n, v);
  if (!(crack_length > 0)) return result;  // pressing straight towards the base
  const double threshold = patch.toughness * crack_length;
  const double tolerance = 1e-12 * threshold;
  result.direction = v;
  result.threshold = threshold;
  const auto drive = [&](const ContactAreas& areas, const Eigen::Vector3d& delta) {
    return opening_force(contact_field(patch, contact, areas, delta).force, n, v);
  };
  const ContactAreas now = contact_areas(patch, state, contact.triangle);
  const double trial = drive(now, delta_new);
  if (!(trial > threshold)) return result;
  const ContactRegion region = contact_region(patch, contact);
  const LocalGrowth order = local_growth_order(patch, state, region, contact_position);
  const double local_room = order.total_room();
  if (!(local_room > 0)) {
    result.held = false;  // no crack edge in reach: the force just rises
    return result;
  }
  result.in_reach = true;

  // The elastic part of the move: up to where the opening force reaches the threshold.
  double elastic = 0;
  const double before = drive(now, delta_old);
  if (before < threshold) {
    const auto excess = [&](double tau) { return drive(now, delta_old + tau * move) - threshold; };
    elastic = bracketed_root(excess, 0.0, 1.0, before - threshold, trial - threshold, tolerance);
  }
  const double far_room = front_room(patch, state, &region);
  const double total = std::min(crack_length * (1 - elastic) * motion, local_room + far_room);

  // The opening force minus the threshold after `local` in the region and the rest of
  // `amount` elsewhere.
  const auto excess_after = [&](double local, double amount) {
    return drive(areas_after_growth(patch, state, contact, order, local, amount - local),
                 delta_new) -
           threshold;
  };
  const auto least_local = [&](double amount) { return std::max(0.0, amount - far_room); };
  double amount = total;
  double local = least_local(total);
  const double stiffest = excess_after(local, total);
  if (stiffest < 0) {
    // Even the least growth in the region softens too much: separate less.
    const auto excess = [&](double a) { return excess_after(least_local(a), a); };
    amount = bracketed_root(excess, 0.0, total, trial - threshold, stiffest, tolerance);
    local = least_local(amount);
  } else {
    const double most = std::min(total, local_room);
    const double softest = excess_after(most, total);
    if (softest > 0) {
      local = most;
      result.held = false;
    } else {
      const auto excess = [&](double l) { return excess_after(l, total); };
      local = bracketed_root(excess, local, most, stiffest, softest, tolerance);
    }
  }
  result.separated = apply_local_growth(patch, state, order, local);
  result.separated += grow_nearest(patch, state, contact_position, amount - local, &region);
  result.fracture_motion = result.separated / crack_length;
  return result;
}

double holding_normal_length(const SeparationPatch& patch, int node, int tool_node) {
  const Eigen::Vector3d n = region_normal(patch.positions, patch.triangles, patch.regions.of(node));
  const auto normal_stiffness = [&](FieldState state) {
    const double* block = patch.field(node, tool_node, state);
    const Eigen::Map<const Eigen::Matrix3d> frame(block);
    double k = 0;
    for (int a = 0; a < 3; ++a) k += std::pow(frame.col(a).dot(n), 2) * block[9 + a * patch.degree];
    return k;
  };
  const double k = normal_stiffness(FieldState::connected);
  const double k_bar = normal_stiffness(FieldState::locally_separated);
  if (!(k > k_bar)) return std::numeric_limits<double>::infinity();
  return k * std::sqrt(patch.region_areas[node] / ((k - k_bar) * patch.toughness));
}

PlateauReach plateau_reach(const SeparationPatch& patch) {
  PlateauReach reach;
  reach.nodes = patch.node_count();
  for (int node = 0; node < reach.nodes; ++node) {
    const double length = holding_normal_length(patch, node);
    if (length <= patch.normal_length) ++reach.held;
    if (node == 0 || !(length <= reach.longest)) {
      reach.longest = length;
      reach.where = patch.positions.col(node);
    }
  }
  return reach;
}

std::string plateau_warning(const PlateauReach& reach, double normal_length) {
  if (reach.held == reach.nodes) return {};
  return fmt::format(
      "fracture holds the pull at F_n = J_c l_n at {} of {} interface nodes only: with "
      "normal_length {:.2f} mm a crack front at the others lets the force rise above F_n as it "
      "grows (the longest length needed is {:.2f} mm, at ({:.1f}, {:.1f}, {:.1f}) mm; "
      "normal_length at least that holds it everywhere)",
      reach.held, reach.nodes, 1e3 * normal_length, 1e3 * reach.longest, 1e3 * reach.where.x(),
      1e3 * reach.where.y(), 1e3 * reach.where.z());
}

}  // namespace cohaptic
