#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "common/mesh/boundary_surface.h"
#include "common/mesh/box_mesher.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

TEST(BoxMesher, CountsAndVolumeOfThePaperCube) {
  const TetMesh mesh =
      make_box_mesh(Eigen::Vector3d(-0.065, -0.065, -0.13), Eigen::Vector3d::Constant(0.13),
                    Eigen::Vector3i::Constant(11));
  EXPECT_EQ(mesh.node_count(), 12 * 12 * 12);
  EXPECT_EQ(mesh.tet_count(), 6 * 11 * 11 * 11);
  double volume = 0;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const double v = signed_volume(mesh, t);
    ASSERT_GT(v, 0) << "tet " << t;
    volume += v;
  }
  EXPECT_NEAR(volume, 0.13 * 0.13 * 0.13, 1e-15);
}

TEST(BoxMesher, GradedCellsFormAGeometricSeriesAndFillTheBox) {
  // x: each cell 2 times the one before; y uniform; z: each half the one before.
  const TetMesh mesh = make_box_mesh(Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(7, 1, 1),
                                     Eigen::Vector3i(3, 2, 2), Eigen::Vector3d(2, 1, 0.5));
  // x nodes at 0, 1, 3, 7 (cells 1, 2, 4); z nodes at -1, -1/3, 0 (cells 2/3, 1/3).
  const double x[] = {0, 1, 3, 7}, z[] = {-1, -1.0 / 3, 0};
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d node = mesh.nodes.col(i + 4 * (1 + 3 * k));  // j = 1: y = 0.5
      EXPECT_NEAR(node.x(), x[i], 1e-14);
      EXPECT_NEAR(node.y(), 0.5, 1e-14);
      EXPECT_NEAR(node.z(), z[k], 1e-14);
    }
  double volume = 0;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    ASSERT_GT(signed_volume(mesh, t), 0) << "tet " << t;
    volume += signed_volume(mesh, t);
  }
  EXPECT_NEAR(volume, 7, 1e-13);
  EXPECT_THROW(make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(),
                             Eigen::Vector3i::Ones(), Eigen::Vector3d(1, 0, 1)),
               MeshError);
}

TEST(BoxMesher, UniformCellsComeFirstOnTheFineSide) {
  // x: 2 equal cells, then each 3 times the one before: cells 1, 1, 3, 9 (length 14).
  // z: fine side at the max end: cells 4, 2, 1, 1 from the min (length 8).
  const TetMesh mesh =
      make_box_mesh(Eigen::Vector3d(0, 0, -8), Eigen::Vector3d(14, 1, 8), Eigen::Vector3i(4, 1, 4),
                    Eigen::Vector3d(3, 1, 0.5), Eigen::Vector3i(2, 0, 2));
  const double x[] = {0, 1, 2, 5, 14}, z[] = {-8, -4, -2, -1, 0};
  for (int k = 0; k < 5; ++k)
    for (int i = 0; i < 5; ++i) {
      const Eigen::Vector3d node = mesh.nodes.col(i + 5 * 2 * k);  // j = 0
      EXPECT_NEAR(node.x(), x[i], 1e-13);
      EXPECT_NEAR(node.z(), z[k], 1e-13);
    }
  // With one uniform cell (or none) it is the plain geometric series.
  const TetMesh plain = make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(),
                                      Eigen::Vector3i::Constant(3), Eigen::Vector3d::Constant(1.7));
  const TetMesh one =
      make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), Eigen::Vector3i::Constant(3),
                    Eigen::Vector3d::Constant(1.7), Eigen::Vector3i::Ones());
  EXPECT_LT((plain.nodes - one.nodes).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_THROW(
      make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), Eigen::Vector3i::Constant(2),
                    Eigen::Vector3d::Ones(), Eigen::Vector3i(3, 0, 0)),
      MeshError);
}

TEST(BoundarySurface, BoxSurfaceIsClosedOutwardAndComplete) {
  const int n = 4;
  const TetMesh mesh =
      make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d(2, 3, 5), Eigen::Vector3i(n, n, n));
  const BoundarySurface surface = extract_boundary_surface(mesh);
  EXPECT_EQ(surface.triangle_count(), 6 * n * n * 2);
  EXPECT_EQ(static_cast<int>(surface.nodes.size()),
            (n + 1) * (n + 1) * (n + 1) - (n - 1) * (n - 1) * (n - 1));
  // Divergence theorem: the flux of x through a closed outward surface is the volume.
  double flux = 0;
  for (const Triangle& tri : surface.triangles) {
    const Eigen::Vector3d a = mesh.nodes.col(tri[0]), b = mesh.nodes.col(tri[1]),
                          c = mesh.nodes.col(tri[2]);
    flux += ((a + b + c) / 3.0).dot((b - a).cross(c - a)) / 2.0 / 3.0;
  }
  EXPECT_NEAR(flux, 2.0 * 3.0 * 5.0, 1e-12);
  // Every triangle's centroid lies on a box face, and its normal points out of that face.
  for (const Triangle& tri : surface.triangles) {
    const Eigen::Vector3d centre =
        (mesh.nodes.col(tri[0]) + mesh.nodes.col(tri[1]) + mesh.nodes.col(tri[2])) / 3;
    const Eigen::Vector3d normal = triangle_normal(mesh, tri);
    const Eigen::Vector3d box_centre(1, 1.5, 2.5);
    EXPECT_GT(normal.dot(centre - box_centre), 0);
  }
  // Adjacency: every surface triangle is listed at each of its nodes.
  for (int t = 0; t < surface.triangle_count(); ++t)
    for (int v : surface.triangles[t]) {
      const auto around = surface.node_triangles(v);
      EXPECT_NE(std::find(around.begin(), around.end(), t), around.end());
    }
}

}  // namespace
}  // namespace cohaptic
