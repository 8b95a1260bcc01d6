#include "common/mesh/boundary_surface.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <fmt/format.h>
#include <unordered_map>

#include "common/util/error.h"

namespace cohaptic {
namespace {

// Faces of a positively oriented tetrahedron, each counter-clockwise seen from outside.
constexpr int kOutwardFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

struct FaceKey {
  std::array<int, 3> sorted;
  bool operator==(const FaceKey&) const = default;
};

struct FaceKeyHash {
  std::size_t operator()(const FaceKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (int v : k.sorted) {
      h ^= static_cast<std::uint64_t>(v);
      h *= 1099511628211ull;
    }
    return h;
  }
};

struct FaceUse {
  int count = 0;
  int tet = -1;
  Triangle oriented{};
};

}  // namespace

BoundarySurface extract_boundary_surface(const TetMesh& mesh) {
  std::unordered_map<FaceKey, FaceUse, FaceKeyHash> faces;
  faces.reserve(mesh.tets.size() * 2);
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const Tet& e = mesh.tets[t];
    for (const auto& f : kOutwardFaces) {
      Triangle tri{e[f[0]], e[f[1]], e[f[2]]};
      FaceKey key{tri};
      std::sort(key.sorted.begin(), key.sorted.end());
      FaceUse& use = faces[key];
      if (++use.count > 2) {
        throw MeshError(fmt::format(
            "non-manifold volume: the face with nodes {} {} {} belongs to more than two "
            "tetrahedra (one is element {})",
            mesh.node_tags[tri[0]], mesh.node_tags[tri[1]], mesh.node_tags[tri[2]],
            mesh.tet_tags[t]));
      }
      use.tet = t;
      use.oriented = tri;
    }
  }

  BoundarySurface surface;
  for (const auto& [key, use] : faces) {
    if (use.count == 1) {
      surface.triangles.push_back(use.oriented);
      surface.triangle_tet.push_back(use.tet);
    }
  }
  // Hash-map order is arbitrary: sort so that the surface is reproducible run to run.
  std::vector<std::size_t> order(surface.triangles.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return surface.triangle_tet[a] != surface.triangle_tet[b]
               ? surface.triangle_tet[a] < surface.triangle_tet[b]
               : surface.triangles[a] < surface.triangles[b];
  });
  std::vector<Triangle> triangles;
  std::vector<int> triangle_tet;
  triangles.reserve(order.size());
  triangle_tet.reserve(order.size());
  for (std::size_t i : order) {
    triangles.push_back(surface.triangles[i]);
    triangle_tet.push_back(surface.triangle_tet[i]);
  }
  surface.triangles = std::move(triangles);
  surface.triangle_tet = std::move(triangle_tet);

  const auto n = static_cast<std::size_t>(mesh.node_count());
  surface.node_triangle_offsets.assign(n + 1, 0);
  for (const Triangle& tri : surface.triangles)
    for (int v : tri) ++surface.node_triangle_offsets[v + 1];
  for (std::size_t i = 0; i < n; ++i) {
    if (surface.node_triangle_offsets[i + 1] > 0) surface.nodes.push_back(static_cast<int>(i));
    surface.node_triangle_offsets[i + 1] += surface.node_triangle_offsets[i];
  }
  surface.node_triangle_list.resize(static_cast<std::size_t>(surface.node_triangle_offsets[n]));
  std::vector<int> fill(surface.node_triangle_offsets.begin(),
                        surface.node_triangle_offsets.end() - 1);
  for (int t = 0; t < surface.triangle_count(); ++t)
    for (int v : surface.triangles[t])
      surface.node_triangle_list[static_cast<std::size_t>(fill[v]++)] = t;
  surface.triangle_neighbours = triangle_edge_neighbours(surface.triangles);
  return surface;
}

std::vector<std::array<int, 3>> triangle_edge_neighbours(const std::vector<Triangle>& triangles) {
  const auto edge_key = [](int from, int to) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(from)) << 32) |
           static_cast<std::uint32_t>(to);
  };
  // Directed edge -> owning triangle; -1 once the same directed edge is seen twice.
  std::unordered_map<std::uint64_t, int> owner;
  owner.reserve(triangles.size() * 3);
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t)
    for (int k = 0; k < 3; ++k) {
      const auto [it, inserted] =
          owner.emplace(edge_key(triangles[t][k], triangles[t][(k + 1) % 3]), t);
      if (!inserted) it->second = -1;
    }
  std::vector<std::array<int, 3>> neighbours(triangles.size(), {-1, -1, -1});
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t)
    for (int k = 0; k < 3; ++k) {
      const auto forward = owner.find(edge_key(triangles[t][k], triangles[t][(k + 1) % 3]));
      const auto reverse = owner.find(edge_key(triangles[t][(k + 1) % 3], triangles[t][k]));
      if (forward->second >= 0 && reverse != owner.end() && reverse->second >= 0)
        neighbours[t][k] = reverse->second;
    }
  return neighbours;
}

Eigen::Vector3d triangle_normal(const TetMesh& mesh, const Triangle& tri) {
  const Eigen::Vector3d x0 = mesh.nodes.col(tri[0]);
  return (mesh.nodes.col(tri[1]) - x0).cross(mesh.nodes.col(tri[2]) - x0).normalized();
}

}  // namespace cohaptic
