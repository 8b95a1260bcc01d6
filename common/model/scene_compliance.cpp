#include "common/model/scene_compliance.h"

#include "common/model/compliance_setup.h"

namespace cohaptic {

SceneCompliance prepare_scene_compliance(const Model& model, bool whole_surface,
                                         const std::optional<std::filesystem::path>& cache_directory) {
  SceneCompliance compliance;
  for (const BodyModel& body_model : model.bodies) {
    const auto* body = std::get_if<ElasticBody>(&body_model);
    if (!body) {
      compliance.per_body.push_back(nullptr);
      continue;
    }
    auto& columns = compliance.owned.emplace_back(
        std::make_unique<ComplianceColumns>(body->free_factor, body->dofs, compliance_row_nodes(*body, whole_surface)));
    prepare_compliance(*body, *columns, cache_directory);
    compliance.per_body.push_back(columns.get());
  }
  return compliance;
}

void save_scene_compliance(const Model& model, const SceneCompliance& compliance, const std::filesystem::path& cache_directory) {
  for (std::size_t i = 0; i < model.bodies.size(); ++i)
    if (const auto* body = std::get_if<ElasticBody>(&model.bodies[i]); body && body->spec.compliance.disk_cache)
      save_compliance(*body, *compliance.per_body[i], cache_directory);
}

}  // namespace cohaptic
