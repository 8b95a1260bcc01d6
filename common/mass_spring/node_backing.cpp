#include "common/mass_spring/node_backing.h"

#include <fmt/format.h>

#include <algorithm>

#include "common/util/error.h"

namespace cohaptic {

void add_node_backing_forces(const NodeBacking& backing, const Eigen::Ref<const Eigen::Matrix3Xd>& positions,
                             Eigen::Ref<Eigen::Matrix3Xd> forces) noexcept {
  const auto count = static_cast<Eigen::Index>(backing.nodes.size());
  for (Eigen::Index i = 0; i < count; ++i) {
    Eigen::Vector3d force = backing.offset.segment<3>(3 * i);
    for (Eigen::Index j = 0; j < count; ++j) {
      const Eigen::Vector3d gap =
          positions.col(backing.nodes[static_cast<std::size_t>(j)]) - backing.targets.segment<3>(3 * j);
      force.noalias() -= backing.stiffness.block<3, 3>(3 * i, 3 * j) * gap;
    }
    if (force.dot(backing.normals.segment<3>(3 * i)) >= 0) forces.col(backing.nodes[static_cast<std::size_t>(i)]) += force;
  }
}

NodeBacking sub_network_backing(const NodeBacking& whole, std::span<const std::int32_t> body_nodes,
                                const Eigen::Ref<const Eigen::Matrix3Xd>& body_positions) {
  // local[k]: the local node of whole.nodes[k], or -1 outside the sub-network.
  std::vector<int> local(whole.nodes.size(), -1);
  std::vector<Eigen::Index> kept;
  for (std::size_t k = 0; k < whole.nodes.size(); ++k) {
    const auto at = std::find(body_nodes.begin(), body_nodes.end(), whole.nodes[k]);
    if (at == body_nodes.end()) continue;
    local[k] = static_cast<int>(at - body_nodes.begin());
    kept.push_back(static_cast<Eigen::Index>(k));
  }
  NodeBacking sub;
  const auto size = 3 * static_cast<Eigen::Index>(kept.size());
  sub.stiffness.resize(size, size);
  sub.targets.resize(size);
  sub.offset.resize(size);
  sub.normals.resize(size);
  for (std::size_t a = 0; a < kept.size(); ++a) {
    const Eigen::Index i = kept[a];
    const auto row = 3 * static_cast<Eigen::Index>(a);
    sub.nodes.push_back(local[static_cast<std::size_t>(i)]);
    sub.targets.segment<3>(row) = whole.targets.segment<3>(3 * i);
    sub.offset.segment<3>(row) = whole.offset.segment<3>(3 * i);
    sub.normals.segment<3>(row) = whole.normals.segment<3>(3 * i);
    for (std::size_t b = 0; b < kept.size(); ++b)
      sub.stiffness.block<3, 3>(row, 3 * static_cast<Eigen::Index>(b)) =
          whole.stiffness.block<3, 3>(3 * i, 3 * kept[b]);
    for (std::size_t j = 0; j < whole.nodes.size(); ++j) {
      if (local[j] >= 0) continue;
      const auto column = 3 * static_cast<Eigen::Index>(j);
      const Eigen::Vector3d gap = body_positions.col(whole.nodes[j]) - whole.targets.segment<3>(column);
      sub.offset.segment<3>(row) -= whole.stiffness.block<3, 3>(3 * i, column) * gap;
    }
  }
  return sub;
}

void check_node_backing(const NodeBacking& backing, int node_count, const char* what) {
  const auto size = 3 * static_cast<Eigen::Index>(backing.nodes.size());
  if (backing.stiffness.rows() != size || backing.stiffness.cols() != size || backing.targets.size() != size ||
      backing.offset.size() != size || backing.normals.size() != size)
    throw Error(fmt::format("{}: the backing of {} nodes needs a {}x{} stiffness and {} targets, offsets and normals, "
                            "not {}x{}, {}, {} and {}",
                            what, backing.nodes.size(), size, size, size, backing.stiffness.rows(),
                            backing.stiffness.cols(), backing.targets.size(), backing.offset.size(),
                            backing.normals.size()));
  for (std::size_t k = 0; k < backing.nodes.size(); ++k) {
    const int node = backing.nodes[k];
    if (node < 0 || node >= node_count)
      throw Error(fmt::format("{}: backed node {} is {}, not a node of the {}", what, k, node, node_count));
    if (std::count(backing.nodes.begin(), backing.nodes.end(), node) > 1)
      throw Error(fmt::format("{}: node {} is backed twice", what, node));
  }
  if (!backing.stiffness.allFinite() || !backing.targets.allFinite() || !backing.offset.allFinite() ||
      !backing.normals.allFinite())
    throw Error(fmt::format("{}: the backing's stiffness, targets, offsets or normals are not finite", what));
}

}  // namespace cohaptic
