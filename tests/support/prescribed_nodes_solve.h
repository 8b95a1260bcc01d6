// The independent answer for a body whose surface nodes are displaced by another body:
// the full sparse static solve (CHOLMOD over K_UU) with those nodes prescribed along their
// free axes, and the forces read from it. Units: m, N.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "common/fem/static_solve.h"
#include "common/model/elastic_body.h"

namespace cohaptic::testing {

/// Full sparse solve of `body` with `nodes` (ascending) prescribed at `displacement`
/// (3 per node) along their free axes.
StaticSolution prescribed_nodes_solve(const ElasticBody& body, const std::vector<int>& nodes,
                                      const Eigen::VectorXd& displacement);

/// The 3 values of each of `nodes` in a global 3N vector.
Eigen::VectorXd nodal(const Eigen::VectorXd& global, const std::vector<int>& nodes);

/// The full solve's reactions at `nodes` along their free axes (a fixed axis's reaction
/// is the support's, not the interaction's).
Eigen::VectorXd free_reactions(const ElasticBody& body, const Eigen::VectorXd& reaction,
                               const std::vector<int>& nodes);

}  // namespace cohaptic::testing
