// NearestTriangleCandidates (common/contact/nearest_triangle_candidates.h) and
// AabbTree::triangles_near: the tree query against a brute-force box test; the nearest-
// triangle rules over the candidates against the same rules over every triangle (the full
// scans), bit for bit, on a box mesh with a touchable face (a lattice of points with many
// exact ties at edges and vertices, and random points) and on the brain's surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <random>
#include <vector>

#include "common/contact/find_contact.h"
#include "common/contact/nearest_triangle_candidates.h"
#include "common/mesh/box_mesher.h"
#include "common/mesh/mesh_checks.h"
#include "common/mesh/read_gmsh.h"
#include "support/test_meshes.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;

double box_distance(const Vector3d& p, const Vector3d& lo, const Vector3d& hi) {
  return (p - p.cwiseMax(lo).cwiseMin(hi)).norm();
}

TEST(AabbTree, TrianglesNearAreExactlyThoseWhoseBoxesAreWithinReach) {
  const TriangleSurface sphere = testing::make_icosphere(3, 1.0);
  const AabbTree tree(sphere);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-1.5, 1.5), reach(0, 0.4);
  std::vector<int> found;
  for (int i = 0; i < 300; ++i) {
    const Vector3d p(coordinate(rng), coordinate(rng), coordinate(rng));
    const double r = reach(rng);
    found.clear();
    tree.triangles_near(p, r, found);
    std::sort(found.begin(), found.end());
    std::vector<int> expected;
    for (int t = 0; t < sphere.triangle_count(); ++t) {
      const Triangle& tri = sphere.triangles[t];
      const Vector3d a = sphere.vertices.col(tri[0]), b = sphere.vertices.col(tri[1]),
                     c = sphere.vertices.col(tri[2]);
      if (box_distance(p, a.cwiseMin(b).cwiseMin(c), a.cwiseMax(b).cwiseMax(c)) <= r)
        expected.push_back(t);
    }
    ASSERT_EQ(found, expected) << "point " << p.transpose() << ", reach " << r;
  }
}

// The rules over the candidates give the very triangle, point and distance of the full scans.
int expect_same_as_full_scans(const TetMesh& mesh, const BoundarySurface& surface,
                              const std::vector<int>& touchable,
                              const std::vector<Vector3d>& points) {
  const SurfacePseudoNormals normals = compute_pseudo_normals(mesh, surface);
  const NearestTriangleCandidates candidates(mesh, surface, touchable);
  std::vector<int> all_near, touchable_near;
  std::size_t most = 0;
  for (const Vector3d& p : points) {
    SCOPED_TRACE(::testing::Message() << "point " << p.transpose());
    candidates.find(p, all_near, touchable_near);
    most = std::max(most, all_near.size());
    const SurfacePoint full = closest_surface_point(mesh, surface, normals, p);
    const SurfacePoint pruned = closest_surface_point(mesh, surface, normals, p, all_near);
    EXPECT_EQ(pruned.triangle, full.triangle);
    EXPECT_EQ(pruned.signed_distance, full.signed_distance);
    const SurfacePoint nearest = nearest_triangle(mesh, surface, normals, touchable, p);
    const SurfacePoint nearest_pruned = nearest_triangle(mesh, surface, normals, touchable_near, p);
    EXPECT_EQ(nearest_pruned.triangle, nearest.triangle);
    EXPECT_EQ(nearest_pruned.closest.point, nearest.closest.point);
    EXPECT_EQ(nearest_pruned.signed_distance, nearest.signed_distance);
    for (double radius : {0.0, 0.05}) {
      const ContactQuery contact = find_contact(mesh, surface, normals, touchable, p, radius);
      const ContactQuery contact_pruned =
          find_contact(mesh, surface, normals, touchable_near, p, radius, all_near);
      EXPECT_EQ(contact_pruned.signed_distance, contact.signed_distance);
      EXPECT_EQ(contact_pruned.contact.has_value(), contact.contact.has_value());
      if (contact.contact && contact_pruned.contact) {
        EXPECT_EQ(contact_pruned.contact->triangle, contact.contact->triangle);
        EXPECT_EQ(contact_pruned.contact->displacement, contact.contact->displacement);
      }
    }
  }
  return static_cast<int>(most);
}

TEST(NearestTriangleCandidates, GiveTheFullScansAnswersOnABoxWithATouchableFace) {
  const TetMesh mesh =
      make_box_mesh(Vector3d::Zero(), Vector3d(1.0, 0.8, 0.6), Eigen::Vector3i(5, 4, 3));
  const BoundarySurface surface = extract_boundary_surface(mesh);
  std::vector<int> top;  // the face z = 0.6
  for (int t = 0; t < surface.triangle_count(); ++t) {
    const Triangle& tri = surface.triangles[t];
    if (mesh.nodes(2, tri[0]) == 0.6 && mesh.nodes(2, tri[1]) == 0.6 &&
        mesh.nodes(2, tri[2]) == 0.6)
      top.push_back(t);
  }
  ASSERT_GT(top.size(), 10u);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> x(-0.3, 1.3), y(-0.3, 1.1), z(-0.3, 0.9);
  std::uniform_int_distribution<int> lattice(-2, 12);
  std::vector<Vector3d> points;
  for (int i = 0; i < 1500; ++i) points.emplace_back(x(rng), y(rng), z(rng));
  // On the mesh's lattice and halfway between: exact ties at vertices, edges and faces.
  for (int i = 0; i < 1500; ++i)
    points.emplace_back(0.1 * lattice(rng), 0.1 * lattice(rng), 0.1 * lattice(rng));
  const int most = expect_same_as_full_scans(mesh, surface, top, points);
  std::printf("  box: %d surface triangles, at most %d candidates per point\n",
              surface.triangle_count(), most);
}

TEST(NearestTriangleCandidates, GiveTheFullScansAnswersOnTheBrain) {
  const std::filesystem::path file =
      std::filesystem::path(COHAPTIC_SOURCE_DIR) / "scenes/brain/brain.msh";
  TetMesh mesh = read_gmsh(file).mesh;
  check_tet_mesh(mesh);  // orients the tetrahedra, so that the surface faces outwards
  mesh.nodes *= 1e-3;
  const BoundarySurface surface = extract_boundary_surface(mesh);
  std::vector<int> every(static_cast<std::size_t>(surface.triangle_count()));
  for (int t = 0; t < surface.triangle_count(); ++t) every[static_cast<std::size_t>(t)] = t;
  std::mt19937 rng(13);
  std::uniform_int_distribution<int> pick(0, surface.triangle_count() - 1);
  std::normal_distribution<double> offset(0, 0.004);
  std::vector<Vector3d> points;
  for (int i = 0; i < 2000; ++i) {
    const Triangle& tri = surface.triangles[pick(rng)];
    points.push_back(mesh.nodes.col(tri[i % 3]) + Vector3d(offset(rng), offset(rng), offset(rng)));
  }
  for (int i = 0; i < 200; ++i)
    points.push_back(mesh.nodes.col(surface.triangles[pick(rng)][0]));  // at vertices
  const int most = expect_same_as_full_scans(mesh, surface, every, points);
  std::printf("  brain: %d surface triangles, at most %d candidates per point\n",
              surface.triangle_count(), most);
}

}  // namespace
}  // namespace cohaptic
