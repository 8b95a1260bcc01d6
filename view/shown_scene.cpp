#include "view/shown_scene.h"

#include <fmt/format.h>

#include "common/mesh/boundary_surface.h"
#include "common/util/error.h"

namespace cohaptic::view {
namespace {

// Appends the part showing `shown_nodes` of a body whose nodes are at `positions`, with the
// body's `triangles` whose three corners are shown.
ShownPart& append_shown_part(ShownScene& scene, const Eigen::Matrix3Xd& positions,
                             std::span<const int> shown_nodes,
                             std::span<const Triangle> triangles) {
  ShownPart& part = scene.parts.emplace_back();
  part.offset = scene.node_count();
  part.nodes.assign(shown_nodes.begin(), shown_nodes.end());
  part.index_of.assign(static_cast<std::size_t>(positions.cols()), -1);
  scene.rest.conservativeResize(3, part.offset + part.size());
  for (int k = 0; k < part.size(); ++k) {
    const int node = part.nodes[static_cast<std::size_t>(k)];
    part.index_of[static_cast<std::size_t>(node)] = part.offset + k;
    scene.rest.col(part.offset + k) = positions.col(node);
  }
  for (const Triangle& tri : triangles) {
    const Triangle shown = {part.index_of[static_cast<std::size_t>(tri[0])],
                            part.index_of[static_cast<std::size_t>(tri[1])],
                            part.index_of[static_cast<std::size_t>(tri[2])]};
    if (shown[0] >= 0 && shown[1] >= 0 && shown[2] >= 0) scene.triangles.push_back(shown);
  }
  return part;
}

struct ShownPartMaker {
  ShownScene& scene;
  ComplianceColumns* columns;

  void operator()(const ElasticBody& body) const {
    if (!columns)
      throw Error(fmt::format("live view: no compliance columns for the linear elastic object '{}'",
                              body.name));
    ShownPart& part =
        append_shown_part(scene, body.mesh.nodes, columns->row_nodes(), body.surface.triangles);
    for (int node : part.nodes) {
      part.row_positions.push_back(columns->row_position(node));
      part.shown_of_tag[body.mesh.node_tags[static_cast<std::size_t>(node)]] =
          part.index_of[static_cast<std::size_t>(node)];
    }
  }
  void operator()(const MassSpringModel& body) const {
    append_shown_part(scene, body.network.rest_positions, body.network.surface_nodes,
                      body.network.triangles);
  }
  void operator()(const HomeSpringBody& body) const {
    std::vector<int> vertices(static_cast<std::size_t>(body.display.rest.cols()));
    for (std::size_t v = 0; v < vertices.size(); ++v) vertices[v] = static_cast<int>(v);
    append_shown_part(scene, body.display.rest, vertices, body.surface.triangles).display =
        &body.display;
  }
  void operator()(const SeparationModel& body) const {
    const TetMesh& pulled = body.bodies.pulled.mesh;
    const TetMesh& base = body.bodies.base.mesh;
    const int base_first =
        pulled.node_count();  // the base's nodes numbered on after the pulled layer's
    Eigen::Matrix3Xd positions(3, pulled.node_count() + base.node_count());
    positions << pulled.nodes, base.nodes;
    const BoundarySurface pulled_surface = extract_boundary_surface(pulled);
    const BoundarySurface base_surface = extract_boundary_surface(base);
    std::vector<int> nodes = pulled_surface.nodes;
    std::vector<Triangle> triangles = pulled_surface.triangles;
    for (int node : base_surface.nodes) nodes.push_back(base_first + node);
    for (const Triangle& tri : base_surface.triangles)
      triangles.push_back({base_first + tri[0], base_first + tri[1], base_first + tri[2]});
    append_shown_part(scene, positions, nodes, triangles);
  }
};

}  // namespace

int ShownScene::of_node(int body, int node) const {
  const std::vector<int>& index_of = parts[static_cast<std::size_t>(body)].index_of;
  return node >= 0 && static_cast<std::size_t>(node) < index_of.size()
             ? index_of[static_cast<std::size_t>(node)]
             : -1;
}

int ShownScene::of_tag(int body, std::int64_t tag) const {
  const auto& tags = parts[static_cast<std::size_t>(body)].shown_of_tag;
  const auto found = tags.find(tag);
  return found == tags.end() ? -1 : found->second;
}

ShownScene shown_scene(const Model& model, std::span<ComplianceColumns* const> columns) {
  ShownScene scene;
  scene.rest.resize(3, 0);
  for (std::size_t i = 0; i < model.bodies.size(); ++i)
    std::visit(ShownPartMaker{scene, i < columns.size() ? columns[i] : nullptr}, model.bodies[i]);
  return scene;
}

}  // namespace cohaptic::view
