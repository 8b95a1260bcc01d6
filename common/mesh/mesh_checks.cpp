#include "common/mesh/mesh_checks.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <map>
#include <numeric>
#include <set>
#include <unordered_map>

#include "common/util/error.h"

namespace cohaptic {
namespace {

constexpr int kMaxNamed = 5;  // how many offenders a message names before "and N more"

std::string name_some(const std::vector<std::string>& names) {
  std::string out;
  for (int i = 0; i < std::min<int>(kMaxNamed, static_cast<int>(names.size())); ++i)
    out += (i ? ", " : "") + names[i];
  if (static_cast<int>(names.size()) > kMaxNamed)
    out += fmt::format(" and {} more", names.size() - kMaxNamed);
  return out;
}

double longest_edge(const TetMesh& mesh, const Tet& tet) {
  double longest = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
      longest = std::max(longest, (mesh.nodes.col(tet[i]) - mesh.nodes.col(tet[j])).norm());
  return longest;
}

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(static_cast<std::size_t>(n)) {
    std::iota(parent.begin(), parent.end(), 0);
  }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};

void check_duplicate_nodes(const TetMesh& mesh, double tolerance, MeshCheckReport& report) {
  if (mesh.node_count() == 0) return;
  // Bucket nodes on a grid of cell `tolerance`; coincident nodes share a bucket or a neighbour.
  // Cells are relative to the bounding box's corner, so coordinates far from the origin
  // cannot overflow the cell index.
  const Eigen::Vector3d origin = mesh.nodes.rowwise().minCoeff();
  using Cell = Eigen::Matrix<std::int64_t, 3, 1>;
  const auto cell_of = [&](const Eigen::Vector3d& x) {
    return Cell(((x - origin) / tolerance).array().floor().cast<std::int64_t>());
  };
  const auto key = [](const Cell& c) {
    std::uint64_t h = 1469598103934665603ull;
    for (int i = 0; i < 3; ++i) h = (h ^ static_cast<std::uint64_t>(c[i])) * 1099511628211ull;
    return h;
  };
  std::unordered_multimap<std::uint64_t, int> buckets;
  buckets.reserve(static_cast<std::size_t>(mesh.node_count()));
  std::vector<std::string> pairs;
  for (int n = 0; n < mesh.node_count(); ++n) {
    const Eigen::Vector3d x = mesh.nodes.col(n);
    const Cell c = cell_of(x);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto range = buckets.equal_range(
              key(c + Cell(std::int64_t{dx}, std::int64_t{dy}, std::int64_t{dz})));
          for (auto it = range.first; it != range.second; ++it)
            if ((mesh.nodes.col(it->second) - x).norm() <= tolerance)
              pairs.push_back(
                  fmt::format("{} and {}", mesh.node_tags[it->second], mesh.node_tags[n]));
        }
    buckets.emplace(key(c), n);
  }
  if (!pairs.empty())
    report.warnings.push_back(
        fmt::format("{} pair(s) of coincident nodes (the mesh is cracked there): nodes {}",
                    pairs.size(), name_some(pairs)));
}

void check_connectivity(const TetMesh& mesh, MeshCheckReport& report) {
  // Tetrahedra sharing a face belong to the same part.
  UnionFind parts(mesh.tet_count());
  std::map<std::array<int, 3>, int> face_owner;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const Tet& e = mesh.tets[t];
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> face{};
      for (int i = 0, k = 0; i < 4; ++i)
        if (i != skip) face[k++] = e[i];
      std::sort(face.begin(), face.end());
      const auto [it, inserted] = face_owner.emplace(face, t);
      if (!inserted) parts.unite(t, it->second);
    }
  }
  std::map<int, std::pair<int, int>> part_size_and_first;  // root -> (size, first tet)
  for (int t = 0; t < mesh.tet_count(); ++t) {
    auto& entry = part_size_and_first.try_emplace(parts.find(t), 0, t).first->second;
    ++entry.first;
  }
  report.parts = static_cast<int>(part_size_and_first.size());
  if (report.parts > 1) {
    std::vector<std::string> names;
    for (const auto& [root, info] : part_size_and_first)
      names.push_back(fmt::format("{} elements containing node {}", info.first,
                                  mesh.node_tags[mesh.tets[info.second][0]]));
    report.warnings.push_back(
        fmt::format("the mesh has {} disconnected parts (each needs its own fixed region): {}",
                    report.parts, name_some(names)));
  }
}

}  // namespace

double min_dihedral_angle_deg(const TetMesh& mesh, int t) {
  const Tet& e = mesh.tets[t];
  // Face normals (not oriented consistently); the dihedral angle at edge (i,j) is between
  // the two faces containing it, i.e. those opposite the other two nodes k and l.
  Eigen::Vector3d normal[4];
  for (int skip = 0; skip < 4; ++skip) {
    int v[3], k = 0;
    for (int i = 0; i < 4; ++i)
      if (i != skip) v[k++] = e[i];
    Eigen::Vector3d n = (mesh.nodes.col(v[1]) - mesh.nodes.col(v[0]))
                            .cross(mesh.nodes.col(v[2]) - mesh.nodes.col(v[0]));
    // Orient outward: away from the skipped node.
    if (n.dot(mesh.nodes.col(e[skip]) - mesh.nodes.col(v[0])) > 0) n = -n;
    normal[skip] = n.normalized();
  }
  double smallest = 180;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) {
      const double cosine = std::clamp(-normal[a].dot(normal[b]), -1.0, 1.0);
      smallest = std::min(smallest, std::acos(cosine) * 180.0 / M_PI);
    }
  return smallest;
}

MeshCheckReport check_tet_mesh(TetMesh& mesh, const MeshCheckOptions& options) {
  MeshCheckReport report;
  if (mesh.tet_count() == 0) throw MeshError("the mesh has no tetrahedra");
  if (!mesh.nodes.allFinite()) throw MeshError("the mesh has non-finite node coordinates");

  std::vector<std::string> degenerate, negative;
  int positive_count = 0;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const double volume = signed_volume(mesh, t);
    const double edge = longest_edge(mesh, mesh.tets[t]);
    if (std::abs(volume) <= options.degenerate_volume_ratio * edge * edge * edge)
      degenerate.push_back(fmt::format("{} (volume {:.3g})", mesh.tet_tags[t], volume));
    else if (volume < 0)
      negative.push_back(std::to_string(mesh.tet_tags[t]));
    else
      ++positive_count;
  }
  if (!degenerate.empty())
    throw MeshError(fmt::format("{} zero-volume tetrahedra: element {}", degenerate.size(),
                                name_some(degenerate)));
  if (!negative.empty() && positive_count > 0)
    throw MeshError(
        fmt::format("{} inverted tetrahedra (negative volume while {} others are positive; the "
                    "mesh is tangled): element {}",
                    negative.size(), positive_count, name_some(negative)));
  if (!negative.empty()) {
    for (Tet& tet : mesh.tets) std::swap(tet[2], tet[3]);
    report.notes.push_back("all tetrahedra were negatively oriented: reoriented");
  }

  std::vector<std::string> slivers;
  report.min_dihedral_deg = 180;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const double angle = min_dihedral_angle_deg(mesh, t);
    report.min_dihedral_deg = std::min(report.min_dihedral_deg, angle);
    if (angle < options.sliver_angle_deg)
      slivers.push_back(fmt::format("{} ({:.3g} deg)", mesh.tet_tags[t], angle));
  }
  if (!slivers.empty())
    report.warnings.push_back(
        fmt::format("{} sliver tetrahedra (smallest dihedral angle below {} deg; they make the "
                    "stiffness ill-conditioned): "
                    "element {}",
                    slivers.size(), options.sliver_angle_deg, name_some(slivers)));

  const double diagonal =
      (mesh.nodes.rowwise().maxCoeff() - mesh.nodes.rowwise().minCoeff()).norm();
  check_duplicate_nodes(mesh, std::max(options.duplicate_tolerance * diagonal, 1e-300), report);
  check_connectivity(mesh, report);
  return report;
}

std::vector<std::string> check_boundary_surface(const TetMesh& mesh,
                                                const BoundarySurface& surface) {
  std::vector<std::string> findings;
  std::set<std::pair<int, int>> non_manifold_edges;
  for (int t = 0; t < surface.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = surface.triangles[t][k], b = surface.triangles[t][(k + 1) % 3];
      if (surface.triangle_neighbours[t][k] < 0)
        non_manifold_edges.emplace(std::min(a, b), std::max(a, b));
    }
  std::vector<std::string> edges;
  for (const auto& [a, b] : non_manifold_edges)
    edges.push_back(fmt::format("{}-{}", mesh.node_tags[a], mesh.node_tags[b]));
  if (!edges.empty())
    findings.push_back(
        fmt::format("{} non-manifold surface edge(s) (more than two surface triangles meet): {}",
                    edges.size(), name_some(edges)));
  // A manifold surface vertex has one fan of triangles: walking neighbours around it
  // from any of its triangles reaches all of them.
  std::vector<std::string> vertices;
  for (int node : surface.nodes) {
    const auto around = surface.node_triangles(node);
    std::vector<int> fan{around[0]};
    for (std::size_t i = 0; i < fan.size(); ++i) {
      for (int neighbour : surface.triangle_neighbours[fan[i]]) {
        if (neighbour < 0) continue;
        const Triangle& tri = surface.triangles[neighbour];
        const bool touches = std::find(tri.begin(), tri.end(), node) != tri.end();
        if (touches && std::find(fan.begin(), fan.end(), neighbour) == fan.end())
          fan.push_back(neighbour);
      }
    }
    if (fan.size() != around.size()) vertices.push_back(std::to_string(mesh.node_tags[node]));
  }
  if (!vertices.empty())
    findings.push_back(fmt::format(
        "{} non-manifold surface vertex(es) (parts of the surface touch at a point): node {}",
        vertices.size(), name_some(vertices)));
  return findings;
}

std::vector<std::string> check_triangle_surface(const TriangleSurface& surface,
                                                const std::string& name) {
  std::vector<std::string> findings;
  std::map<std::pair<int, int>, int> edge_uses;
  for (const Triangle& tri : surface.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      ++edge_uses[{std::min(a, b), std::max(a, b)}];
    }
  std::vector<std::string> open, non_manifold;
  for (const auto& [edge, uses] : edge_uses) {
    const std::string label = fmt::format("{}-{}", edge.first, edge.second);
    if (uses == 1) open.push_back(label);
    if (uses > 2) non_manifold.push_back(label);
  }
  if (!open.empty())
    findings.push_back(fmt::format("{}: open surface, {} boundary edge(s) between vertices {}",
                                   name, open.size(), name_some(open)));
  if (!non_manifold.empty())
    findings.push_back(fmt::format("{}: {} non-manifold edge(s) between vertices {}", name,
                                   non_manifold.size(), name_some(non_manifold)));
  return findings;
}

}  // namespace cohaptic
