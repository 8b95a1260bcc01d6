#include "support/tissue_sheet.h"

#include <cmath>

namespace cohaptic::testing {

TriangleSurface equilateral_sheet(int columns, int rows, double spacing) {
  TriangleSurface sheet;
  const double row_height = spacing * std::sqrt(3.0) / 2;
  const auto index = [columns](int i, int j) { return i + (columns + 1) * j; };
  sheet.vertices.resize(3, (columns + 1) * (rows + 1));
  // Odd rows are shifted by half a spacing; the whole sheet is centred on the origin.
  const Eigen::Vector3d centre(0.5 * (columns + 0.5) * spacing, 0.5 * rows * row_height, 0);
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i <= columns; ++i)
      sheet.vertices.col(index(i, j)) =
          Eigen::Vector3d((i + 0.5 * (j % 2)) * spacing, j * row_height, 0) - centre;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i) {
      if (j % 2 == 0) {
        sheet.triangles.push_back({index(i, j), index(i + 1, j), index(i, j + 1)});
        sheet.triangles.push_back({index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)});
      } else {
        sheet.triangles.push_back({index(i, j), index(i + 1, j + 1), index(i, j + 1)});
        sheet.triangles.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      }
    }
  return sheet;
}

}  // namespace cohaptic::testing
