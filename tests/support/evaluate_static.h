// The force of a static IR body (the condensed FEM body) for the tests: evaluate_force with
// the empty evaluation state such a body has (under the sphere contact model: a cold solve);
// dt is unused by it.
#pragma once

#include <span>

#include "common/ir/evaluate_force.h"

namespace cohaptic::testing {

inline ForceSample evaluate_static(const PreparedIR& prepared, const Eigen::Vector3d& own_tool,
                                   std::span<const Eigen::Vector3d> remote_tools) noexcept {
  EvaluationState stateless;
  return evaluate_force(prepared, stateless, own_tool, remote_tools, 0);
}

}  // namespace cohaptic::testing
