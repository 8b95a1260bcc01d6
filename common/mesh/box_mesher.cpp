#include "common/mesh/box_mesher.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "common/util/error.h"

namespace cohaptic {
namespace {

// Where node i of n cells lies along an axis, as a fraction of its length: `uniform`
// equal cells on the fine side, then a geometric series of ratio r (r < 1: mirrored, the
// fine side at the max end).
double graded_fraction(int i, int n, double r, int uniform) {
  if (r < 1) return 1 - graded_fraction(n - i, n, 1 / r, uniform);
  // The length of the first `cells` cells, in units of the first cell.
  const auto length = [&](int cells) {
    const int equal = std::min(cells, std::max(uniform, 1));
    const int grown = cells - equal;
    return equal + (std::abs(r - 1) < 1e-12 ? grown : r * (std::pow(r, grown) - 1) / (r - 1));
  };
  return i == n ? 1 : length(i) / length(n);
}

}  // namespace

TetMesh make_box_mesh(const Eigen::Vector3d& min_corner, const Eigen::Vector3d& size,
                      const Eigen::Vector3i& divisions, const Eigen::Vector3d& grading,
                      const Eigen::Vector3i& uniform_cells) {
  if ((divisions.array() < 1).any())
    throw MeshError(fmt::format("box mesh: divisions must be >= 1 along every axis, got {} {} {}",
                                divisions.x(), divisions.y(), divisions.z()));
  if (!(size.array() > 0).all() || !size.allFinite())
    throw MeshError(fmt::format("box mesh: size must be positive along every axis, got {} {} {}",
                                size.x(), size.y(), size.z()));
  if (!(grading.array() > 0).all() || !grading.allFinite())
    throw MeshError(
        fmt::format("box mesh: grading must be a positive ratio along every axis, got {} {} {}",
                    grading.x(), grading.y(), grading.z()));
  if ((uniform_cells.array() < 0).any() || (uniform_cells.array() > divisions.array()).any())
    throw MeshError(fmt::format(
        "box mesh: uniform cells must be from 0 to the divisions along every axis, got {} {} {}",
        uniform_cells.x(), uniform_cells.y(), uniform_cells.z()));
  const int nx = divisions.x(), ny = divisions.y(), nz = divisions.z();
  const auto node_id = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };

  TetMesh mesh;
  const int node_count = (nx + 1) * (ny + 1) * (nz + 1);
  mesh.nodes.resize(3, node_count);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        mesh.nodes.col(node_id(i, j, k)) =
            min_corner + size.cwiseProduct(Eigen::Vector3d(
                             graded_fraction(i, nx, grading.x(), uniform_cells.x()),
                             graded_fraction(j, ny, grading.y(), uniform_cells.y()),
                             graded_fraction(k, nz, grading.z(), uniform_cells.z())));
  mesh.node_tags.resize(static_cast<std::size_t>(node_count));
  for (int n = 0; n < node_count; ++n) mesh.node_tags[n] = n + 1;

  // The six paths from corner (0,0,0) to (1,1,1) that step one axis at a time.
  constexpr int kAxisOrders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                     {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
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
          if (signed_volume(mesh, mesh.tet_count() - 1) < 0)
            std::swap(mesh.tets.back()[2], mesh.tets.back()[3]);
        }
  mesh.tet_tags.resize(mesh.tets.size());
  for (int t = 0; t < mesh.tet_count(); ++t) mesh.tet_tags[t] = t + 1;
  return mesh;
}

}  // namespace cohaptic
