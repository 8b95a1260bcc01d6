#include "common/mass_spring/network_stiffness.h"

#include <vector>

namespace cohaptic {

SparseMatrix network_stiffness(const Eigen::Ref<const Eigen::Matrix3Xd>& positions,
                               std::span<const Spring> springs) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(36 * springs.size());
  for (const Spring& spring : springs) {
    const Eigen::Vector3d l = positions.col(spring.b) - positions.col(spring.a);
    const double length = l.norm();
    if (!(length > 0)) continue;  // a collapsed spring has no direction (and no force)
    const Eigen::Vector3d n = l / length;
    const Eigen::Matrix3d nn = n * n.transpose();
    const Eigen::Matrix3d block = spring.stiffness * (nn + (1 - spring.rest_length / length) *
                                                               (Eigen::Matrix3d::Identity() - nn));
    const int nodes[2] = {spring.a, spring.b};
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            entries.emplace_back(3 * nodes[i] + r, 3 * nodes[j] + c,
                                 (i == j ? 1.0 : -1.0) * block(r, c));
  }
  const auto size = 3 * positions.cols();
  SparseMatrix stiffness(size, size);
  stiffness.setFromTriplets(entries.begin(), entries.end());
  return stiffness;
}

}  // namespace cohaptic
