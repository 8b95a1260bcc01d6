#include "common/mesh/box_mesher.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {
namespace {

// Where node i of n cells lies along an axis, as a fraction of its length: the cells
// form a geometric series of ratio r.
double graded_fraction(int i, int n, double r) {
  if (i == n) return 1;
  if (std::abs(r - 1) < 1e-12) return double(i) / n;
  return (std::pow(r, i) - 1) / (std::pow(r, n) - 1);
}

}  // namespace

TetMesh make_box_mesh(const Eigen::Vector3d& min_corner, const Eigen::Vector3d& size,
                      const Eigen::Vector3i& divisions, const Eigen::Vector3d& grading) {
  if ((divisions.array() < 1).any())
    throw MeshError(fmt::format("box mesh: divisions must be >= 1 along every axis, got {} {} {}",
                                divisions.x(), divisions.y(), divisions.z()));
  if (!(size.array() > 0).all() || !size.allFinite())
    throw MeshError(fmt::format("box mesh: size must be positive along every axis, got {} {} {}",
                                size.x(), size.y(), size.z()));
  if (!(grading.array() > 0).all() || !grading.allFinite())
    throw MeshError(fmt::format("box mesh: grading must be a positive ratio along every axis, got {} {} {}",
                                grading.x(), grading.y(), grading.z()));
  const int nx = divisions.x(), ny = divisions.y(), nz = divisions.z();
  const auto node_id = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };

  TetMesh mesh;
  const int node_count = (nx + 1) * (ny + 1) * (nz + 1);
  mesh.nodes.resize(3, node_count);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        mesh.nodes.col(node_id(i, j, k)) =
            min_corner + size.cwiseProduct(Eigen::Vector3d(graded_fraction(i, nx, grading.x()), graded_fraction(j, ny, grading.y()),
                                                          graded_fraction(k, nz, grading.z())));
  mesh.node_tags.resize(static_cast<std::size_t>(node_count));
  for (int n = 0; n < node_count; ++n) mesh.node_tags[n] = n + 1;

  // The six paths from corner (0,0,0) to (1,1,1) that step one axis at a time.
  constexpr int kAxisOrders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  mesh.tets.reserve(static_cast<std::size_t>(6) * nx * ny * nz);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& order : kAxisOrders) {
          int step[3] = {i, j, k};
          Tet tet{};
          tet[0] = node_id(step[0], step[1], step[2]);
          for (int s = 0; s < 3; ++s) {
            ++step[order[s]];
            tet[s + 1] = node_id(step[0], step[1], step[2]);
          }
          mesh.tets.push_back(tet);
          if (signed_volume(mesh, mesh.tet_count() - 1) < 0) std::swap(mesh.tets.back()[2], mesh.tets.back()[3]);
        }
  mesh.tet_tags.resize(mesh.tets.size());
  for (int t = 0; t < mesh.tet_count(); ++t) mesh.tet_tags[t] = t + 1;
  return mesh;
}

}  // namespace cohaptic
