// The force of a static IR body (the condensed FEM body) for the tests: evaluate_force with
// a fresh evaluation state (under the sphere contact model: its solve from the server's
// contacts, with no work budget); dt is unused by it.
#pragma once

#include <limits>
#include <span>
#include <variant>

#include "common/ir/evaluate_force.h"

namespace cohaptic::testing {

inline ForceSample evaluate_static(const PreparedIR& prepared, const Eigen::Vector3d& own_tool,
                                   std::span<const Eigen::Vector3d> remote_tools) {
  EvaluationState fresh = make_evaluation_state(prepared);
  if (auto* fem = std::get_if<FemEvaluation>(&fresh.body); fem && fem->sphere)
    fem->sphere->work_budget = std::numeric_limits<double>::infinity();
  return evaluate_force(prepared, fresh, own_tool, remote_tools, 0);
}

}  // namespace cohaptic::testing
