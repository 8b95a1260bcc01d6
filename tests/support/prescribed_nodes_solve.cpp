#include "support/prescribed_nodes_solve.h"

#include <algorithm>

namespace cohaptic::testing {

StaticSolution prescribed_nodes_solve(const ElasticBody& body, const std::vector<int>& nodes,
                                      const Eigen::VectorXd& displacement) {
  std::vector<int> dofs;
  for (int node : nodes)
    for (int axis = 0; axis < 3; ++axis)
      if (!body.dofs.is_fixed(node, axis)) dofs.push_back(3 * node + axis);
  Eigen::VectorXd values(static_cast<Eigen::Index>(dofs.size()));
  for (std::size_t i = 0; i < dofs.size(); ++i) {
    const auto j = std::lower_bound(nodes.begin(), nodes.end(), dofs[i] / 3) - nodes.begin();
    values[static_cast<Eigen::Index>(i)] = displacement[3 * j + dofs[i] % 3];
  }
  return ConstrainedStaticSolver(body.stiffness, body.dofs, dofs).solve(values);
}

Eigen::VectorXd nodal(const Eigen::VectorXd& global, const std::vector<int>& nodes) {
  Eigen::VectorXd values(3 * static_cast<Eigen::Index>(nodes.size()));
  for (std::size_t j = 0; j < nodes.size(); ++j)
    values.segment<3>(3 * static_cast<Eigen::Index>(j)) = global.segment<3>(3 * nodes[j]);
  return values;
}

Eigen::VectorXd free_reactions(const ElasticBody& body, const Eigen::VectorXd& reaction,
                               const std::vector<int>& nodes) {
  Eigen::VectorXd values = nodal(reaction, nodes);
  for (std::size_t j = 0; j < nodes.size(); ++j)
    for (int axis = 0; axis < 3; ++axis)
      if (body.dofs.is_fixed(nodes[j], axis)) values[3 * static_cast<Eigen::Index>(j) + axis] = 0;
  return values;
}

}  // namespace cohaptic::testing
