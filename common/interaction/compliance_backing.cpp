#include "common/interaction/compliance_backing.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace cohaptic {

Eigen::MatrixXd target_normal_compliance(std::span<const PolygonCollision> collisions, ComplianceColumns& columns) {
  const auto count = static_cast<Eigen::Index>(collisions.size());
  std::vector<int> polygon_nodes;
  for (const PolygonCollision& collision : collisions)
    polygon_nodes.insert(polygon_nodes.end(), collision.polygon.begin(), collision.polygon.end());
  std::sort(polygon_nodes.begin(), polygon_nodes.end());
  polygon_nodes.erase(std::unique(polygon_nodes.begin(), polygon_nodes.end()), polygon_nodes.end());
  columns.compute_columns(polygon_nodes);
  Eigen::MatrixXd compliance(count, count);
  for (Eigen::Index j = 0; j < count; ++j) {
    const PolygonCollision& cj = collisions[static_cast<std::size_t>(j)];
    for (Eigen::Index i = 0; i <= j; ++i) {
      const PolygonCollision& ci = collisions[static_cast<std::size_t>(i)];
      double value = 0;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          value += ci.weights[a] * cj.weights[b] * ci.normal.dot(columns.block(ci.polygon[a], cj.polygon[b]) * cj.normal);
      compliance(i, j) = value;
      compliance(j, i) = value;  // exactly symmetric, as the wire and the check want
    }
  }
  return compliance;
}

NodeBacking compliance_backing(std::span<const PolygonCollision> collisions, ComplianceColumns& columns,
                               const Eigen::Ref<const Eigen::VectorXd>& masses, double time_step,
                               double damping_ratio) {
  const auto count = static_cast<Eigen::Index>(collisions.size());
  NodeBacking backing;
  backing.compliance = target_normal_compliance(collisions, columns);
  backing.offsets = Eigen::VectorXd::Zero(count);
  backing.damping.resize(count);
  backing.targets.resize(3 * count);
  backing.normals.resize(3 * count);
  for (Eigen::Index i = 0; i < count; ++i) {
    const PolygonCollision& collision = collisions[static_cast<std::size_t>(i)];
    const double mass = masses[collision.active];
    backing.nodes.push_back(collision.active);
    backing.compliance(i, i) += time_step * time_step / mass;
    backing.damping[i] = 2 * damping_ratio * std::sqrt(mass / backing.compliance(i, i));
    backing.targets.segment<3>(3 * i) = collision.target;
    backing.normals.segment<3>(3 * i) = collision.normal;
  }
  return backing;
}

}  // namespace cohaptic
