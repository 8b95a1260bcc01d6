#include "common/laparoscopy/tissue_grid.h"

namespace cohaptic {

TriangleSurface tissue_grid(const TissueGridSpec& grid) {
  const int nx = grid.divisions.x(), ny = grid.divisions.y();
  const auto index = [nx](int i, int j) { return i + (nx + 1) * j; };
  TriangleSurface sheet;
  sheet.vertices.resize(3, (nx + 1) * (ny + 1));
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i)
      sheet.vertices.col(index(i, j)) =
          grid.min + Eigen::Vector3d(grid.size.x() * i / nx, grid.size.y() * j / ny, 0);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      sheet.triangles.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      sheet.triangles.push_back({index(i, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  return sheet;
}

}  // namespace cohaptic
