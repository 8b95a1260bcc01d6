#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <unordered_map>

#include "common/mesh/box_mesher.h"
#include "common/mesh/read_freesurfer.h"
#include "common/mesh/read_gmsh.h"
#include "common/model/model.h"
#include "common/scene/load_scene.h"
#include "common/util/stopwatch.h"

namespace cohaptic {
namespace {

TetMesh load_mesh(const Scene& scene) {
  const MeshSpec& spec = scene.object.mesh;
  if (spec.box) return make_box_mesh(spec.box->min_corner, spec.box->size, spec.box->divisions);
  GmshMesh gmsh = read_gmsh(spec.file);
  if (gmsh.unused_nodes_dropped > 0)
    spdlog::info("{}: dropped {} nodes that no tetrahedron uses", spec.file.string(), gmsh.unused_nodes_dropped);
  gmsh.mesh.nodes *= scene.metres_per_unit;
  return std::move(gmsh.mesh);
}

Obstacle load_obstacle(const ObstacleSpec& spec, double metres_per_unit) {
  Obstacle obstacle;
  obstacle.name = spec.name;
  obstacle.plane = spec.plane;
  if (!spec.surface_file.empty()) {
    obstacle.surface = read_freesurfer_ascii(spec.surface_file);
    obstacle.surface.vertices *= metres_per_unit;
    for (const std::string& finding : check_triangle_surface(obstacle.surface, "obstacle " + spec.name))
      spdlog::warn("{}", finding);
  }
  return obstacle;
}

}  // namespace

std::string Model::describe_dof(int dof) const {
  return fmt::format("node {} axis {}", mesh.node_tags[dof / 3], "xyz"[dof % 3]);
}

std::vector<int> select_nodes(const NodeSelector& selector, const TetMesh& mesh, const BoundarySurface& surface,
                              bool surface_only) {
  std::vector<bool> on_surface(static_cast<std::size_t>(mesh.node_count()), false);
  for (int node : surface.nodes) on_surface[node] = true;
  const double diagonal = (mesh.nodes.rowwise().maxCoeff() - mesh.nodes.rowwise().minCoeff()).norm();
  const double tolerance = selector.tolerance.value_or(1e-6 * diagonal);

  std::vector<int> selected;
  if (selector.kind == NodeSelector::Kind::node_tags) {
    std::unordered_map<std::int64_t, int> index_of_tag;
    for (int n = 0; n < mesh.node_count(); ++n) index_of_tag.emplace(mesh.node_tags[n], n);
    for (std::int64_t tag : selector.node_tags) {
      const auto it = index_of_tag.find(tag);
      if (it == index_of_tag.end())
        throw SceneError(fmt::format("{}: node {} is not in the mesh (or no tetrahedron uses it)", selector.where, tag));
      if (surface_only && !on_surface[it->second])
        throw SceneError(fmt::format("{}: node {} is not on the surface", selector.where, tag));
      selected.push_back(it->second);
    }
  } else {
    for (int n = 0; n < mesh.node_count(); ++n) {
      if (surface_only && !on_surface[n]) continue;
      const Eigen::Vector3d x = mesh.nodes.col(n);
      bool chosen = false;
      switch (selector.kind) {
        case NodeSelector::Kind::surface: chosen = on_surface[n]; break;
        case NodeSelector::Kind::box:
          chosen = ((x.array() >= selector.box_min.array() - tolerance) &&
                    (x.array() <= selector.box_max.array() + tolerance)).all();
          break;
        case NodeSelector::Kind::plane:
          chosen = std::abs((x - selector.plane_point).dot(selector.plane_normal)) <= tolerance;
          break;
        case NodeSelector::Kind::node_tags: break;
      }
      if (chosen) selected.push_back(n);
    }
  }
  std::sort(selected.begin(), selected.end());
  selected.erase(std::unique(selected.begin(), selected.end()), selected.end());
  if (selected.empty())
    throw SceneError(fmt::format("{}: selects no {}node of the mesh (check coordinates and units)", selector.where,
                                 surface_only ? "surface " : ""));
  return selected;
}

Model build_model(const Scene& scene) {
  Model model;
  model.scene = scene;
  validate(scene.object.material);

  Stopwatch watch;
  model.mesh = load_mesh(scene);
  model.mesh_report = check_tet_mesh(model.mesh);
  for (const std::string& note : model.mesh_report.notes) spdlog::info("mesh: {}", note);
  for (const std::string& warning : model.mesh_report.warnings) spdlog::warn("mesh: {}", warning);
  model.surface = extract_boundary_surface(model.mesh);
  for (const std::string& finding : check_boundary_surface(model.mesh, model.surface)) spdlog::warn("mesh: {}", finding);
  model.normals = compute_pseudo_normals(model.mesh, model.surface);

  std::vector<AxisMask> fixed_axes(static_cast<std::size_t>(model.mesh.node_count()), 0);
  for (const FixedRegion& region : scene.object.fixed)
    for (int node : select_nodes(region.nodes, model.mesh, model.surface, false))
      fixed_axes[node] = static_cast<AxisMask>(fixed_axes[node] | region.axes);
  model.dofs = make_dof_map(std::move(fixed_axes));

  std::vector<bool> touchable(static_cast<std::size_t>(model.mesh.node_count()), false);
  for (const NodeSelector& selector : scene.object.touchable)
    for (int node : select_nodes(selector, model.mesh, model.surface, true)) touchable[node] = true;
  for (int node = 0; node < model.mesh.node_count(); ++node)
    if (touchable[node]) model.touchable_nodes.push_back(node);
  for (int t = 0; t < model.surface.triangle_count(); ++t) {
    const Triangle& tri = model.surface.triangles[t];
    if (touchable[tri[0]] && touchable[tri[1]] && touchable[tri[2]]) model.touchable_triangles.push_back(t);
  }
  if (model.touchable_triangles.empty())
    throw SceneError(fmt::format("{}: objects[0].touchable selects {} surface nodes but no whole surface triangle",
                                 scene.file.string(), model.touchable_nodes.size()));

  for (const ObstacleSpec& spec : scene.obstacles) model.obstacles.push_back(load_obstacle(spec, scene.metres_per_unit));
  model.timings.mesh_ms = watch.lap_ms();

  model.stiffness = assemble_stiffness(model.mesh, scene.object.material);
  model.timings.assemble_ms = watch.lap_ms();

  model.free_factor = std::make_unique<SparseCholesky>(
      restrict_to_dofs(model.stiffness, model.dofs.free_dofs),
      [&model](int row) { return model.describe_dof(model.dofs.free_dofs[row]); });
  model.timings.factor_ms = watch.lap_ms();

  spdlog::info("model '{}': {} nodes, {} tetrahedra, {} surface triangles, {} free dofs, {} touchable nodes",
               scene.name, model.mesh.node_count(), model.mesh.tet_count(), model.surface.triangle_count(),
               model.dofs.free_count(), model.touchable_nodes.size());
  return model;
}

std::vector<std::int64_t> fixed_node_tags(const Model& model) {
  std::vector<std::int64_t> tags;
  for (int node = 0; node < model.dofs.node_count(); ++node)
    if (model.dofs.fixed_axes[node] != 0) tags.push_back(model.mesh.node_tags[node]);
  std::sort(tags.begin(), tags.end());
  return tags;
}

}  // namespace cohaptic
