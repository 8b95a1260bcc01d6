#include "common/ir/warm_start_sphere_contact.h"

#include <utility>

namespace cohaptic {

bool warm_start_sphere_contact(PreparedIR& prepared, const Eigen::Vector3d& own,
                               std::span<const Eigen::Vector3d> remotes) {
  const auto* fem = std::get_if<CondensedFemIr>(&prepared.ir.body);
  if (!fem || fem->contact_model != ContactModel::sphere || !fem->sphere || !own.allFinite())
    return false;
  EvaluationState state = make_evaluation_state(prepared);
  SphereContactState& sphere = *std::get<FemEvaluation>(state.body).sphere;
  sphere.work_budget = kWarmStartWork;
  // The condensed FEM body ignores dt and the buttons.
  const ForceSample sample = evaluate_force(prepared, state, own, remotes, 0);
  if (sample.flags & (kContactUnresolved | kNonFinite)) return false;
  std::get<PreparedFem>(prepared.body).sphere.start = std::move(sphere.solve);
  return true;
}

}  // namespace cohaptic
