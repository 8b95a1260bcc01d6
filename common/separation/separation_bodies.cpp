#include "common/separation/separation_bodies.h"

#include <algorithm>
#include <fmt/format.h>
#include <map>

#include "common/mesh/boundary_surface.h"
#include "common/mesh/box_mesher.h"
#include "common/util/error.h"

namespace cohaptic {

SeparationInterface find_interface(const SeparationBodies& bodies, double tolerance) {
  if (!(tolerance > 0))
    throw Error(fmt::format("separation interface: tolerance must be positive, got {}", tolerance));
  const TetMesh& pulled = bodies.pulled.mesh;
  const TetMesh& base = bodies.base.mesh;
  const BoundarySurface pulled_surface = extract_boundary_surface(pulled);
  const BoundarySurface base_surface = extract_boundary_surface(base);

  // Base boundary nodes sorted by x: each pulled node searches a window of width 2 tolerance.
  std::vector<int> base_by_x = base_surface.nodes;
  std::sort(base_by_x.begin(), base_by_x.end(),
            [&](int a, int b) { return base.nodes(0, a) < base.nodes(0, b); });
  std::vector<int> partner(static_cast<std::size_t>(pulled.node_count()), -1);
  for (int node : pulled_surface.nodes) {
    const Eigen::Vector3d p = pulled.nodes.col(node);
    auto it = std::lower_bound(base_by_x.begin(), base_by_x.end(), p.x() - tolerance,
                               [&](int b, double x) { return base.nodes(0, b) < x; });
    for (; it != base_by_x.end() && base.nodes(0, *it) <= p.x() + tolerance; ++it) {
      if ((base.nodes.col(*it) - p).norm() > tolerance) continue;
      if (partner[node] >= 0)
        throw Error(fmt::format(
            "separation interface: pulled node {} has two base nodes ({} and {}) within {} m",
            pulled.node_tags[node], base.node_tags[partner[node]], base.node_tags[*it], tolerance));
      partner[node] = *it;
    }
  }

  std::map<std::array<int, 3>, int> base_triangles;  // sorted base nodes -> count
  for (const Triangle& t : base_surface.triangles) {
    std::array<int, 3> key = t;
    std::sort(key.begin(), key.end());
    ++base_triangles[key];
  }

  SeparationInterface interface;
  std::vector<int> interface_index(static_cast<std::size_t>(pulled.node_count()), -1);
  for (const Triangle& t : pulled_surface.triangles) {
    if (partner[t[0]] < 0 || partner[t[1]] < 0 || partner[t[2]] < 0) continue;
    std::array<int, 3> key{partner[t[0]], partner[t[1]], partner[t[2]]};
    std::sort(key.begin(), key.end());
    if (base_triangles.count(key) == 0) continue;
    Triangle local{};
    for (int k = 0; k < 3; ++k) {
      int& index = interface_index[t[k]];
      if (index < 0) {
        index = interface.node_count();
        interface.pulled_nodes.push_back(t[k]);
        interface.base_nodes.push_back(partner[t[k]]);
      }
      local[k] = index;
    }
    // The pulled body's outward normal points into the base: reverse it.
    interface.triangles.push_back({local[0], local[2], local[1]});
  }
  if (interface.triangles.empty())
    throw Error(fmt::format(
        "separation interface: the bodies share no boundary triangle within {} m", tolerance));

  interface.positions.resize(3, interface.node_count());
  for (int k = 0; k < interface.node_count(); ++k)
    interface.positions.col(k) = pulled.nodes.col(interface.pulled_nodes[k]);
  interface.neighbours = triangle_edge_neighbours(interface.triangles);
  interface.open_rim.assign(interface.triangles.size(), 0);
  for (int t = 0; t < interface.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k)
      if (interface.neighbours[t][k] < 0)
        interface.open_rim[t] |= static_cast<std::uint8_t>(1u << k);
  return interface;
}

void seal_rim_edges(SeparationInterface& interface, const std::function<bool(int)>& sealed_node) {
  for (int t = 0; t < interface.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) {
      if ((interface.open_rim[t] >> k & 1u) == 0) continue;
      const Triangle& tri = interface.triangles[t];
      if (sealed_node(tri[k]) && sealed_node(tri[(k + 1) % 3]))
        interface.open_rim[t] &= static_cast<std::uint8_t>(~(1u << k));
    }
}

SeparationBodies make_two_layer_boxes(const TwoLayerBoxes& boxes) {
  if (boxes.pulled_layers < 1 || boxes.base_layers < 1)
    throw Error(fmt::format("two-layer boxes: layers must be >= 1, got pulled {} and base {}",
                            boxes.pulled_layers, boxes.base_layers));
  if (!(boxes.pulled_thickness > 0) || !(boxes.base_thickness > 0))
    throw Error(
        fmt::format("two-layer boxes: thicknesses must be positive, got pulled {} m and base {} m",
                    boxes.pulled_thickness, boxes.base_thickness));
  validate(boxes.pulled_material);
  validate(boxes.base_material);
  const double a = boxes.size.x(), b = boxes.size.y();
  SeparationBodies bodies;
  bodies.pulled.mesh =
      make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d(a, b, boxes.pulled_thickness),
                    Eigen::Vector3i(boxes.divisions.x(), boxes.divisions.y(), boxes.pulled_layers));
  bodies.base.mesh = make_box_mesh(
      Eigen::Vector3d(0, 0, -boxes.base_thickness), Eigen::Vector3d(a, b, boxes.base_thickness),
      Eigen::Vector3i(boxes.divisions.x(), boxes.divisions.y(), boxes.base_layers));
  bodies.pulled.material = boxes.pulled_material;
  bodies.base.material = boxes.base_material;

  const double on_face = 1e-9 * std::max({a, b, boxes.pulled_thickness, boxes.base_thickness});
  bodies.pulled.fixed_axes.assign(static_cast<std::size_t>(bodies.pulled.mesh.node_count()), 0);
  for (int n = 0; n < bodies.pulled.mesh.node_count(); ++n) {
    const Eigen::Vector3d p = bodies.pulled.mesh.nodes.col(n);
    if (p.x() > a - on_face && p.z() > on_face) bodies.pulled.fixed_axes[n] = kAllAxes;
  }
  bodies.base.fixed_axes.assign(static_cast<std::size_t>(bodies.base.mesh.node_count()), 0);
  for (int n = 0; n < bodies.base.mesh.node_count(); ++n)
    if (bodies.base.mesh.nodes(2, n) < -boxes.base_thickness + on_face)
      bodies.base.fixed_axes[n] = kAllAxes;
  bodies.pulled.mesh.nodes.colwise() += boxes.origin;
  bodies.base.mesh.nodes.colwise() += boxes.origin;
  return bodies;
}

}  // namespace cohaptic
