#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <unordered_map>

#include "common/model/compliance_setup.h"
#include "common/model/elastic_body.h"
#include "common/model/load_mesh.h"
#include "common/scene/load_scene.h"
#include "common/util/stopwatch.h"

namespace cohaptic {
namespace {

// "node <tag> axis <x|y|z>" for global dof `dof`.
std::string dof_name(const std::vector<std::int64_t>& node_tags, int dof) {
  return fmt::format("node {} axis {}", node_tags[static_cast<std::size_t>(dof / 3)],
                     "xyz"[dof % 3]);
}

}  // namespace

std::string ElasticBody::describe_dof(int dof) const { return dof_name(mesh.node_tags, dof); }

std::vector<int> select_nodes(const NodeSelector& selector, const TetMesh& mesh,
                              const BoundarySurface& surface, bool surface_only) {
  std::vector<bool> on_surface(static_cast<std::size_t>(mesh.node_count()), false);
  for (int node : surface.nodes) on_surface[node] = true;
  const double diagonal =
      (mesh.nodes.rowwise().maxCoeff() - mesh.nodes.rowwise().minCoeff()).norm();
  const double tolerance = selector.tolerance.value_or(1e-6 * diagonal);

  std::vector<int> selected;
  if (selector.kind == NodeSelector::Kind::node_tags) {
    const std::unordered_map<std::int64_t, int> index_of_tag = node_indices_by_tag(mesh);
    for (std::int64_t tag : selector.node_tags) {
      const auto it = index_of_tag.find(tag);
      if (it == index_of_tag.end())
        throw SceneError(fmt::format("{}: node {} is not in the mesh (or no tetrahedron uses it)",
                                     selector.where, tag));
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
        case NodeSelector::Kind::surface:
          chosen = on_surface[n];
          break;
        case NodeSelector::Kind::box:
          chosen = ((x.array() >= selector.box_min.array() - tolerance) &&
                    (x.array() <= selector.box_max.array() + tolerance))
                       .all();
          break;
        case NodeSelector::Kind::plane:
          chosen = std::abs((x - selector.plane_point).dot(selector.plane_normal)) <= tolerance;
          break;
        case NodeSelector::Kind::node_tags:
          break;
      }
      if (chosen) selected.push_back(n);
    }
  }
  std::sort(selected.begin(), selected.end());
  selected.erase(std::unique(selected.begin(), selected.end()), selected.end());
  if (selected.empty())
    throw SceneError(fmt::format("{}: selects no {}node of the mesh (check coordinates and units)",
                                 selector.where, surface_only ? "surface " : ""));
  return selected;
}

ElasticBody build_elastic_body(const ObjectSpec& object, const ElasticObjectSpec& spec,
                               double metres_per_unit) {
  ElasticBody body;
  body.name = object.name;
  body.spec = spec;
  validate(spec.material);

  Stopwatch watch;
  body.mesh = load_mesh(spec.mesh, metres_per_unit);
  body.mesh_report = check_tet_mesh(body.mesh);
  for (const std::string& note : body.mesh_report.notes) spdlog::info("mesh: {}", note);
  for (const std::string& warning : body.mesh_report.warnings) spdlog::warn("mesh: {}", warning);
  body.surface = extract_boundary_surface(body.mesh);
  for (const std::string& finding : check_boundary_surface(body.mesh, body.surface))
    spdlog::warn("mesh: {}", finding);
  body.normals = compute_pseudo_normals(body.mesh, body.surface);
  body.surface_tree = AabbTree(body.mesh.nodes, body.surface.triangles);

  std::vector<AxisMask> fixed_axes(static_cast<std::size_t>(body.mesh.node_count()), 0);
  for (const FixedRegion& region : spec.fixed)
    for (int node : select_nodes(region.nodes, body.mesh, body.surface, false))
      fixed_axes[node] = static_cast<AxisMask>(fixed_axes[node] | region.axes);
  body.dofs = make_dof_map(std::move(fixed_axes));

  std::vector<bool> touchable(static_cast<std::size_t>(body.mesh.node_count()), false);
  for (const NodeSelector& selector : spec.touchable)
    for (int node : select_nodes(selector, body.mesh, body.surface, true)) touchable[node] = true;
  for (int node = 0; node < body.mesh.node_count(); ++node)
    if (touchable[node]) body.touchable_nodes.push_back(node);
  for (int t = 0; t < body.surface.triangle_count(); ++t) {
    const Triangle& tri = body.surface.triangles[t];
    if (touchable[tri[0]] && touchable[tri[1]] && touchable[tri[2]])
      body.touchable_triangles.push_back(t);
  }
  if (body.touchable_triangles.empty())
    throw SceneError(
        fmt::format("{}.touchable: selects {} surface nodes but no whole surface triangle",
                    object.where, body.touchable_nodes.size()));
  body.contact_normals = contact_normals(body.mesh, body.surface, body.touchable_triangles);

  body.timings.mesh_ms = watch.lap_ms();

  body.stiffness = assemble_stiffness(body.mesh, spec.material);
  body.timings.assemble_ms = watch.lap_ms();

  // The namer outlives this function's `body` (moved into the model): it keeps what it reads.
  body.free_factor =
      DeferredCholesky(restrict_to_dofs(body.stiffness, body.dofs.free_dofs),
                       [tags = body.mesh.node_tags, free_dofs = body.dofs.free_dofs](int row) {
                         return dof_name(tags, free_dofs[static_cast<std::size_t>(row)]);
                       });

  spdlog::info(
      "object '{}' (linear elastic): {} nodes, {} tetrahedra, {} surface triangles, {} free dofs, "
      "{} touchable nodes",
      object.name, body.mesh.node_count(), body.mesh.tet_count(), body.surface.triangle_count(),
      body.dofs.free_count(), body.touchable_nodes.size());
  return body;
}

std::vector<std::int64_t> fixed_node_tags(const ElasticBody& body) {
  std::vector<std::int64_t> tags;
  for (int node = 0; node < body.dofs.node_count(); ++node)
    if (body.dofs.fixed_axes[node] != 0) tags.push_back(body.mesh.node_tags[node]);
  std::sort(tags.begin(), tags.end());
  return tags;
}

}  // namespace cohaptic
