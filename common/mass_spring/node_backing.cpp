#include "common/mass_spring/node_backing.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "common/util/error.h"

namespace cohaptic {

void add_node_backing_forces(const NodeBacking& backing, const Eigen::Ref<const Eigen::Matrix3Xd>& positions,
                             const Eigen::Ref<const Eigen::Matrix3Xd>& velocities,
                             Eigen::Ref<Eigen::Matrix3Xd> forces) noexcept {
  const auto count = static_cast<Eigen::Index>(backing.nodes.size());
  for (Eigen::Index i = 0; i < count; ++i) {
    const int node = backing.nodes[static_cast<std::size_t>(i)];
    const Eigen::Vector3d normal = backing.normals.segment<3>(3 * i);
    const double gap = (positions.col(node) - backing.targets.segment<3>(3 * i)).dot(normal);
    if (!(gap < 0)) continue;
    const double push = -backing.stiffness[i] * gap - backing.damping[i] * velocities.col(node).dot(normal);
    if (push > 0) forces.col(node) += push * normal;
  }
}

NodeBacking sub_network_backing(const NodeBacking& whole, std::span<const std::int32_t> body_nodes) {
  std::vector<Eigen::Index> kept;
  NodeBacking sub;
  for (std::size_t k = 0; k < whole.nodes.size(); ++k) {
    const auto at = std::find(body_nodes.begin(), body_nodes.end(), whole.nodes[k]);
    if (at == body_nodes.end()) continue;
    sub.nodes.push_back(static_cast<int>(at - body_nodes.begin()));
    kept.push_back(static_cast<Eigen::Index>(k));
  }
  const auto count = static_cast<Eigen::Index>(kept.size());
  sub.stiffness.resize(count);
  sub.damping.resize(count);
  sub.targets.resize(3 * count);
  sub.normals.resize(3 * count);
  for (Eigen::Index a = 0; a < count; ++a) {
    const Eigen::Index i = kept[static_cast<std::size_t>(a)];
    sub.stiffness[a] = whole.stiffness[i];
    sub.damping[a] = whole.damping[i];
    sub.targets.segment<3>(3 * a) = whole.targets.segment<3>(3 * i);
    sub.normals.segment<3>(3 * a) = whole.normals.segment<3>(3 * i);
  }
  return sub;
}

void check_node_backing(const NodeBacking& backing, int node_count, const char* what) {
  const auto count = static_cast<Eigen::Index>(backing.nodes.size());
  if (backing.stiffness.size() != count || backing.damping.size() != count || backing.targets.size() != 3 * count ||
      backing.normals.size() != 3 * count)
    throw Error(fmt::format("{}: the backing of {} nodes needs {} stiffnesses and dampings and {} targets and normals, "
                            "not {}, {}, {} and {}",
                            what, count, count, 3 * count, backing.stiffness.size(), backing.damping.size(),
                            backing.targets.size(), backing.normals.size()));
  for (std::size_t k = 0; k < backing.nodes.size(); ++k) {
    const int node = backing.nodes[k];
    if (node < 0 || node >= node_count)
      throw Error(fmt::format("{}: backed node {} is {}, not a node of the {}", what, k, node, node_count));
    if (std::count(backing.nodes.begin(), backing.nodes.end(), node) > 1)
      throw Error(fmt::format("{}: node {} is backed twice", what, node));
  }
  if (!backing.stiffness.allFinite() || !backing.damping.allFinite() || !backing.targets.allFinite() ||
      !backing.normals.allFinite())
    throw Error(fmt::format("{}: the backing's stiffness, damping, targets or normals are not finite", what));
  for (Eigen::Index k = 0; k < count; ++k) {
    if (backing.stiffness[k] < 0 || backing.damping[k] < 0)
      throw Error(fmt::format("{}: backed node {} has stiffness {} N/m and damping {} N s/m (neither may be negative)",
                              what, k, backing.stiffness[k], backing.damping[k]));
    if (std::abs(backing.normals.segment<3>(3 * k).norm() - 1) > 1e-6)
      throw Error(fmt::format("{}: backed node {} has a normal of length {}, not a unit normal", what, k,
                              backing.normals.segment<3>(3 * k).norm()));
  }
}

}  // namespace cohaptic
