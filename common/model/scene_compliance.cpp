#include "common/model/scene_compliance.h"

#include "common/model/compliance_setup.h"

namespace cohaptic {

SceneCompliance prepare_scene_compliance(
    const Model& model, bool whole_surface,
    const std::optional<std::filesystem::path>& cache_directory) {
  SceneCompliance compliance;
  for (const BodyModel& body_model : model.bodies) {
    const auto* body = std::get_if<ElasticBody>(&body_model);
    if (!body) {
      compliance.per_body.push_back(nullptr);
      compliance.columns_at_load.push_back(0);
      continue;
    }
    auto& columns = compliance.owned.emplace_back(std::make_unique<ComplianceColumns>(
        body->free_factor, body->dofs, compliance_row_nodes(*body, whole_surface)));
    compliance.columns_at_load.push_back(
        prepare_compliance(*body, *columns, cache_directory).columns);
    compliance.per_body.push_back(columns.get());
  }
  return compliance;
}

void save_scene_compliance(const Model& model, const SceneCompliance& compliance,
                           const std::filesystem::path& cache_directory) {
  for (std::size_t i = 0; i < model.bodies.size(); ++i)
    if (const auto* body = std::get_if<ElasticBody>(&model.bodies[i]);
        body && body->spec.compliance.disk_cache &&
        compliance.per_body[i]->column_count() > compliance.columns_at_load[i]) {
      ProgressLog progress("compliance");
      progress.set_phase("saving the columns computed");
      save_compliance(*body, *compliance.per_body[i], cache_directory, &progress);
    }
}

}  // namespace cohaptic
