#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "common/mesh/boundary_surface.h"
#include "common/mesh/box_mesher.h"

namespace cohaptic {
namespace {

TEST(BoxMesher, CountsAndVolumeOfThePaperCube) {
  const TetMesh mesh = make_box_mesh(Eigen::Vector3d(-0.065, -0.065, -0.13), Eigen::Vector3d::Constant(0.13),
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

TEST(BoundarySurface, BoxSurfaceIsClosedOutwardAndComplete) {
  const int n = 4;
  const TetMesh mesh = make_box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d(2, 3, 5), Eigen::Vector3i(n, n, n));
  const BoundarySurface surface = extract_boundary_surface(mesh);
  EXPECT_EQ(surface.triangle_count(), 6 * n * n * 2);
  EXPECT_EQ(static_cast<int>(surface.nodes.size()), (n + 1) * (n + 1) * (n + 1) - (n - 1) * (n - 1) * (n - 1));
  // Divergence theorem: the flux of x through a closed outward surface is the volume.
  double flux = 0;
  for (const Triangle& tri : surface.triangles) {
    const Eigen::Vector3d a = mesh.nodes.col(tri[0]), b = mesh.nodes.col(tri[1]), c = mesh.nodes.col(tri[2]);
    flux += ((a + b + c) / 3.0).dot((b - a).cross(c - a)) / 2.0 / 3.0;
  }
  EXPECT_NEAR(flux, 2.0 * 3.0 * 5.0, 1e-12);
  // Every triangle's centroid lies on a box face, and its normal points out of that face.
  for (const Triangle& tri : surface.triangles) {
    const Eigen::Vector3d centre = (mesh.nodes.col(tri[0]) + mesh.nodes.col(tri[1]) + mesh.nodes.col(tri[2])) / 3;
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
