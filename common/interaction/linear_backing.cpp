#include "common/interaction/linear_backing.h"

namespace cohaptic {

LinearBacking build_linear_backing(
    std::span<const PolygonCollision> collisions, const ForcibleDisplacement& displacement,
    const Eigen::MatrixXd& passive_stiffness,
    const Eigen::Ref<const Eigen::Matrix3Xd>& active_rest_positions) {
  LinearBacking backing;
  backing.contact_displacement.resize(3 * static_cast<Eigen::Index>(collisions.size()));
  for (std::size_t k = 0; k < collisions.size(); ++k) {
    backing.nodes.push_back(collisions[k].active);
    backing.contact_displacement.segment<3>(3 * static_cast<Eigen::Index>(k)) =
        collisions[k].target - active_rest_positions.col(collisions[k].active);
  }
  const Eigen::MatrixXd stiffness =
      displacement.map.transpose() * passive_stiffness * displacement.map;
  backing.stiffness = 0.5 * (stiffness + stiffness.transpose());
  return backing;
}

void evaluate_linear_backing(const LinearBacking& backing,
                             const Eigen::Ref<const Eigen::VectorXd>& displacement,
                             Eigen::Ref<Eigen::VectorXd> force) noexcept {
  force.noalias() = backing.stiffness * backing.contact_displacement;
  force.noalias() -= backing.stiffness * displacement;
}

}  // namespace cohaptic
