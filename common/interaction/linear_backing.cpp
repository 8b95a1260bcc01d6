#include "common/interaction/linear_backing.h"

#include <algorithm>
#include <cmath>

namespace cohaptic {

LinearBacking build_linear_backing(std::span<const PolygonCollision> collisions,
                                   const ForcibleDisplacement& displacement, const Eigen::MatrixXd& passive_stiffness,
                                   const Eigen::Ref<const Eigen::Matrix3Xd>& active_rest_positions) {
  LinearBacking backing;
  backing.contact_displacement.resize(3 * static_cast<Eigen::Index>(collisions.size()));
  for (std::size_t k = 0; k < collisions.size(); ++k) {
    backing.nodes.push_back(collisions[k].active);
    backing.contact_displacement.segment<3>(3 * static_cast<Eigen::Index>(k)) =
        collisions[k].target - active_rest_positions.col(collisions[k].active);
  }
  const Eigen::MatrixXd stiffness = displacement.map.transpose() * passive_stiffness * displacement.map;
  backing.stiffness = 0.5 * (stiffness + stiffness.transpose());
  return backing;
}

void evaluate_linear_backing(const LinearBacking& backing, const Eigen::Ref<const Eigen::VectorXd>& displacement,
                             Eigen::Ref<Eigen::VectorXd> force) noexcept {
  force.noalias() = backing.stiffness * backing.contact_displacement;
  force.noalias() -= backing.stiffness * displacement;
}

NodeBacking node_backing(const LinearBacking& backing, std::span<const PolygonCollision> collisions,
                         const Eigen::Ref<const Eigen::VectorXd>& masses, double damping_ratio) {
  const auto count = static_cast<Eigen::Index>(backing.nodes.size());
  NodeBacking nodes{backing.nodes, Eigen::VectorXd(count), Eigen::VectorXd(count), Eigen::VectorXd(3 * count),
                    Eigen::VectorXd(3 * count)};
  for (Eigen::Index i = 0; i < count; ++i) {
    const PolygonCollision& collision = collisions[static_cast<std::size_t>(i)];
    nodes.targets.segment<3>(3 * i) = collision.target;
    nodes.normals.segment<3>(3 * i) = collision.normal;
    double row = 0;
    for (Eigen::Index j = 0; j < count; ++j)
      row += collision.normal.dot(backing.stiffness.block<3, 3>(3 * i, 3 * j) *
                                  collisions[static_cast<std::size_t>(j)].normal);
    const double own = collision.normal.dot(backing.stiffness.block<3, 3>(3 * i, 3 * i) * collision.normal);
    nodes.stiffness[i] = std::max(row > 0 ? row : own, 0.0);
    nodes.damping[i] = 2 * damping_ratio * std::sqrt(nodes.stiffness[i] * masses[collision.active]);
  }
  return nodes;
}

}  // namespace cohaptic
