#include "support/test_meshes.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "common/mesh/box_mesher.h"

namespace cohaptic::testing {

TetMesh distorted_box_mesh(double size, int divisions, double jitter, unsigned seed) {
  TetMesh mesh = make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(size),
                               Eigen::Vector3i::Constant(divisions));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> offset(-jitter * size / divisions,
                                                jitter * size / divisions);
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

TriangleSurface make_icosphere(int level, double radius) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<Eigen::Vector3d> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                                    {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                                    {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  std::vector<Triangle> t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                             {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                             {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                             {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> midpoint;
    const auto middle = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto [it, inserted] = midpoint.emplace(key, static_cast<int>(v.size()));
      if (inserted) v.push_back((v[a] + v[b]) / 2);
      return it->second;
    };
    std::vector<Triangle> finer;
    for (const Triangle& f : t) {
      const int ab = middle(f[0], f[1]), bc = middle(f[1], f[2]), ca = middle(f[2], f[0]);
      finer.insert(finer.end(), {{f[0], ab, ca}, {f[1], bc, ab}, {f[2], ca, bc}, {ab, bc, ca}});
    }
    t = std::move(finer);
  }
  TriangleSurface s;
  s.vertices.resize(3, static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i)
    s.vertices.col(static_cast<Eigen::Index>(i)) = radius * v[i].normalized();
  s.triangles = std::move(t);
  return s;
}

Eigen::Vector3d random_direction(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  for (;;) {
    const Eigen::Vector3d d(normal(rng), normal(rng), normal(rng));
    if (d.norm() > 1e-6) return d.normalized();
  }
}

std::string source_path(const std::string& relative) {
  return std::string(COHAPTIC_SOURCE_DIR) + "/" + relative;
}

}  // namespace cohaptic::testing
