#include "common/ir/prepared_sphere_contact.h"

#include <fmt/format.h>

#include <vector>

#include "common/util/error.h"

namespace cohaptic {

bool SphereWarmStart::active(int node) const noexcept {
  if (node < 0 || node >= kMaxSphereCandidates) return false;
  return (words_[static_cast<std::size_t>(node / 64)] >> (node % 64)) & 1u;
}

void SphereWarmStart::store(std::span<const int> nodes, std::span<const std::uint8_t> active) noexcept {
  words_.fill(0);
  for (std::size_t i = 0; i < nodes.size() && i < active.size(); ++i)
    if (active[i] && nodes[i] >= 0 && nodes[i] < kMaxSphereCandidates)
      words_[static_cast<std::size_t>(nodes[i] / 64)] |= std::uint64_t{1} << (nodes[i] % 64);
}

PreparedSphereContact prepare_sphere_contact(const CondensedFemIr& ir, double tool_radius) {
  if (ir.row_node_count > kMaxSphereCandidates)
    throw Error(fmt::format("intermediate representation: {} contact nodes for the sphere model, at most {}",
                            ir.row_node_count, kMaxSphereCandidates));
  if (!(tool_radius > 0)) throw Error("intermediate representation: the sphere model needs a sphere tool (radius > 0)");
  for (const IrRemoteContact& remote : ir.remotes)
    if (!(remote.tool_radius > 0))
      throw Error(fmt::format("intermediate representation: the sphere model needs a sphere tool, and user {}'s has radius {}",
                              remote.user, remote.tool_radius));
  PreparedSphereContact prepared;
  std::vector<Eigen::Vector3d> outside;
  for (const IrGuardTriangle& guard : ir.guard)
    for (const Eigen::Vector3d& corner : guard.corners) {
      bool contact_node = false;
      for (int i = 0; i < ir.row_node_count && !contact_node; ++i) contact_node = ir.rest_positions.col(i) == corner;
      bool listed = false;
      for (const Eigen::Vector3d& seen : outside) listed |= seen == corner;
      if (!contact_node && !listed) outside.push_back(corner);
    }
  prepared.outside_corners.resize(3, static_cast<Eigen::Index>(outside.size()));
  for (std::size_t i = 0; i < outside.size(); ++i) prepared.outside_corners.col(static_cast<Eigen::Index>(i)) = outside[i];
  return prepared;
}

}  // namespace cohaptic
