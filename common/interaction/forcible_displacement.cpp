#include "common/interaction/forcible_displacement.h"

#include <Eigen/QR>
#include <algorithm>

namespace cohaptic {
namespace {

// Rank decisions relative to the largest singular value: a pair of conditions whose
// weights agree to this are treated as one (they cannot both hold).
constexpr double kRankThreshold = 1e-10;

}  // namespace

Eigen::VectorXd stacked_gaps(std::span<const PolygonCollision> collisions) {
  Eigen::VectorXd gaps(3 * static_cast<Eigen::Index>(collisions.size()));
  for (std::size_t k = 0; k < collisions.size(); ++k)
    gaps.segment<3>(3 * static_cast<Eigen::Index>(k)) = collisions[k].gap;
  return gaps;
}

ForcibleDisplacement forcible_displacement(std::span<const PolygonCollision> collisions,
                                           std::span<const AxisMask> passive_fixed_axes) {
  ForcibleDisplacement result;
  for (const PolygonCollision& collision : collisions)
    result.nodes.insert(result.nodes.end(), collision.polygon.begin(), collision.polygon.end());
  std::sort(result.nodes.begin(), result.nodes.end());
  result.nodes.erase(std::unique(result.nodes.begin(), result.nodes.end()), result.nodes.end());
  const auto position = [&](int node) {
    return static_cast<Eigen::Index>(
        std::lower_bound(result.nodes.begin(), result.nodes.end(), node) - result.nodes.begin());
  };
  const auto node_count = static_cast<Eigen::Index>(result.nodes.size());
  const auto collision_count = static_cast<Eigen::Index>(collisions.size());
  result.map = Eigen::MatrixXd::Zero(3 * node_count, 3 * collision_count);

  if (node_count == 3 * collision_count) {
    // Disjoint polygons: each condition alone, the balance rule w_k / sum w^2 over the
    // polygon's nodes free along the axis (the least-norm solution below, without the
    // decomposition).
    for (Eigen::Index k = 0; k < collision_count; ++k) {
      const PolygonCollision& collision = collisions[static_cast<std::size_t>(k)];
      for (int axis = 0; axis < 3; ++axis) {
        Eigen::Vector3d free_weights = collision.weights;
        for (std::size_t corner = 0; corner < 3; ++corner)
          if ((passive_fixed_axes[static_cast<std::size_t>(collision.polygon[corner])] >> axis) &
              1u)
            free_weights[static_cast<Eigen::Index>(corner)] = 0;
        if (free_weights.norm() <= kRankThreshold) continue;
        const Eigen::Vector3d share = free_weights / free_weights.squaredNorm();
        for (std::size_t corner = 0; corner < 3; ++corner)
          result.map(3 * position(collision.polygon[corner]) + axis, 3 * k + axis) =
              share[static_cast<Eigen::Index>(corner)];
      }
    }
    result.displacement = result.map * stacked_gaps(collisions);
    return result;
  }

  Eigen::MatrixXd conditions(collision_count,
                             node_count);  // row k: w of collision k over the nodes
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> decomposition;
  decomposition.setThreshold(kRankThreshold);
  for (int axis = 0; axis < 3; ++axis) {
    conditions.setZero();
    for (Eigen::Index k = 0; k < collision_count; ++k) {
      const PolygonCollision& collision = collisions[static_cast<std::size_t>(k)];
      for (std::size_t corner = 0; corner < 3; ++corner) {
        const int node = collision.polygon[corner];
        if ((passive_fixed_axes[static_cast<std::size_t>(node)] >> axis) & 1u) continue;
        conditions(k, position(node)) += collision.weights[static_cast<Eigen::Index>(corner)];
      }
    }
    if (conditions.isZero(0)) continue;
    decomposition.compute(conditions);
    const Eigen::MatrixXd least_norm =
        decomposition.pseudoInverse();  // node_count x collision_count
    for (Eigen::Index j = 0; j < node_count; ++j)
      for (Eigen::Index k = 0; k < collision_count; ++k)
        result.map(3 * j + axis, 3 * k + axis) = least_norm(j, k);
  }
  result.displacement = result.map * stacked_gaps(collisions);
  return result;
}

}  // namespace cohaptic
