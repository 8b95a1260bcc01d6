#include "common/interaction/compliance_backing.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "common/util/error.h"

namespace cohaptic {

Eigen::MatrixXd target_normal_compliance(std::span<const PolygonCollision> collisions,
                                         ComplianceColumns& columns) {
  const auto count = static_cast<Eigen::Index>(collisions.size());
  std::vector<int> polygon_nodes;
  for (const PolygonCollision& collision : collisions)
    polygon_nodes.insert(polygon_nodes.end(), collision.polygon.begin(), collision.polygon.end());
  std::sort(polygon_nodes.begin(), polygon_nodes.end());
  polygon_nodes.erase(std::unique(polygon_nodes.begin(), polygon_nodes.end()), polygon_nodes.end());
  columns.compute_columns(polygon_nodes);
  // Each polygon node's column and row once (not a lookup per block: with 117 targets that
  // was most of the time), read as ComplianceColumns::block reads them.
  std::vector<std::array<const ComplianceColumn*, 3>> polygon_columns(collisions.size());
  std::vector<std::array<Eigen::Index, 3>> polygon_rows(collisions.size());
  for (std::size_t j = 0; j < collisions.size(); ++j)
    for (std::size_t k = 0; k < 3; ++k) {
      const int node = collisions[j].polygon[k];
      const int position = columns.row_position(node);
      if (position < 0) throw Error(fmt::format("compliance: node {} is not a row node", node));
      polygon_columns[j][k] = &columns.column(node);
      polygon_rows[j][k] = 3 * static_cast<Eigen::Index>(position);
    }
  Eigen::MatrixXd compliance(count, count);
  for (Eigen::Index j = 0; j < count; ++j) {
    const PolygonCollision& cj = collisions[static_cast<std::size_t>(j)];
    for (Eigen::Index i = 0; i <= j; ++i) {
      const PolygonCollision& ci = collisions[static_cast<std::size_t>(i)];
      double value = 0;
      for (std::size_t a = 0; a < 3; ++a)
        for (std::size_t b = 0; b < 3; ++b) {
          const Eigen::Matrix3d block =
              polygon_columns[static_cast<std::size_t>(j)][b]->middleRows<3>(
                  polygon_rows[static_cast<std::size_t>(i)][a]);
          value += ci.weights[static_cast<Eigen::Index>(a)] *
                   cj.weights[static_cast<Eigen::Index>(b)] * ci.normal.dot(block * cj.normal);
        }
      compliance(i, j) = value;
      compliance(j, i) = value;  // exactly symmetric, as the wire and the check want
    }
  }
  return compliance;
}

NodeBacking compliance_backing(std::span<const PolygonCollision> collisions,
                               ComplianceColumns& columns,
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
