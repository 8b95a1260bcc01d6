#include "support/paired_boxes.h"

#include "common/scene/load_scene.h"

namespace cohaptic::testing {

PairedBoxesRig::PairedBoxesRig(const PairedBoxesOptions& options)
    : model(std::make_unique<Model>(
          build_model(parse_scene(paired_boxes_scene_yaml(options), "paired-boxes.yaml")))),
      front(elastic_body(*model, 0)),
      behind(elastic_body(*model, 1)),
      front_surface(make_surface_adjacency(front.surface.triangles, front.mesh.node_count())),
      behind_surface(make_surface_adjacency(behind.surface.triangles, behind.mesh.node_count())),
      behind_columns(std::make_unique<ComplianceColumns>(behind.free_factor, behind.dofs,
                                                         behind.surface.nodes)) {
  const double face_x = front.mesh.nodes.row(0).maxCoeff();
  for (int node : front.surface.nodes)
    if (front.mesh.nodes(0, node) > face_x - 1e-9) front_face.push_back(node);
}

}  // namespace cohaptic::testing
