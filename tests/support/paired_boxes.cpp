#include "support/paired_boxes.h"

#include <fmt/format.h>

#include "common/scene/load_scene.h"

namespace cohaptic::testing {

std::string paired_boxes_scene_yaml(const PairedBoxesOptions& o) {
  const auto divisions = [](const Eigen::Vector3i& d) { return fmt::format("[{}, {}, {}]", d.x(), d.y(), d.z()); };
  return fmt::format(R"(
units: mm
objects:
  - name: front
    mesh: {{box: {{min: [{0}, 15.95, 0], size: [57.5, 98.9, 57.5], divisions: {1}}}}}
    material: {{youngs_modulus: 1.0e5, poisson_ratio: 0.3}}
    fixed: [{{plane: {{point: [0, 0, 0], normal: [0, 0, 1]}}}}]
    compliance: {{precompute: on_demand, disk_cache: false}}
  - name: behind
    mesh: {{box: {{min: [0, 0, 0], size: [86.5, 130.8, 108.7], divisions: {2}}}}}
    material: {{youngs_modulus: {3}, poisson_ratio: {4}}}
    fixed: [{{plane: {{point: [0, 0, 0], normal: [0, 0, 1]}}}}, {{plane: {{point: [86.5, 0, 0], normal: [1, 0, 0]}}}}]
    touchable: [{{plane: {{point: [0, 0, 0], normal: [1, 0, 0]}}}}]
    compliance: {{precompute: on_demand, disk_cache: false}}
tools: [{{name: A}}]
)",
                     -57.5 - o.gap_mm, divisions(o.front_divisions), divisions(o.behind_divisions),
                     o.behind_youngs_modulus, o.behind_poisson_ratio);
}

PairedBoxesRig::PairedBoxesRig(const PairedBoxesOptions& options)
    : model(std::make_unique<Model>(build_model(parse_scene(paired_boxes_scene_yaml(options), "paired-boxes.yaml")))),
      front(elastic_body(*model, 0)),
      behind(elastic_body(*model, 1)),
      front_surface(make_surface_adjacency(front.surface.triangles, front.mesh.node_count())),
      behind_surface(make_surface_adjacency(behind.surface.triangles, behind.mesh.node_count())),
      behind_columns(std::make_unique<ComplianceColumns>(*behind.free_factor, behind.dofs, behind.surface.nodes)) {
  const double face_x = front.mesh.nodes.row(0).maxCoeff();
  for (int node : front.surface.nodes)
    if (front.mesh.nodes(0, node) > face_x - 1e-9) front_face.push_back(node);
}

}  // namespace cohaptic::testing
