#include "support/test_meshes.h"

#include <random>

#include "common/mesh/box_mesher.h"

namespace cohaptic::testing {

TetMesh distorted_box_mesh(double size, int divisions, double jitter, unsigned seed) {
  TetMesh mesh = make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(size),
                               Eigen::Vector3i::Constant(divisions));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> offset(-jitter * size / divisions, jitter * size / divisions);
  const double tolerance = 1e-12 * size;
  for (int n = 0; n < mesh.node_count(); ++n) {
    for (int axis = 0; axis < 3; ++axis) {
      const double x = mesh.nodes(axis, n);
      const bool on_face = x < tolerance || x > size - tolerance;
      const double delta = offset(rng);
      if (!on_face) mesh.nodes(axis, n) = x + delta;
    }
  }
  return mesh;
}

std::string source_path(const std::string& relative) { return std::string(COHAPTIC_SOURCE_DIR) + "/" + relative; }

}  // namespace cohaptic::testing
