// Mesh validation (common/mesh/mesh_checks.h) and boundary extraction
// (common/mesh/boundary_surface.h) on small meshes built by hand, whose node and element
// tags differ from their indices so that the messages can be checked to name TAGS.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "common/mesh/boundary_surface.h"
#include "common/mesh/box_mesher.h"
#include "common/mesh/mesh_checks.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

constexpr std::int64_t kNodeTagBase = 500;  // node i has tag 500 + i
constexpr std::int64_t kTetTagBase = 100;   // tetrahedron i has tag 100 + i

TetMesh make_mesh(const std::vector<Eigen::Vector3d>& points, const std::vector<Tet>& tets) {
  TetMesh mesh;
  mesh.nodes.resize(3, static_cast<Eigen::Index>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i)
    mesh.nodes.col(static_cast<Eigen::Index>(i)) = points[i];
  mesh.tets = tets;
  for (std::size_t i = 0; i < points.size(); ++i)
    mesh.node_tags.push_back(kNodeTagBase + static_cast<std::int64_t>(i));
  for (std::size_t i = 0; i < tets.size(); ++i)
    mesh.tet_tags.push_back(kTetTagBase + static_cast<std::int64_t>(i));
  return mesh;
}

/// Swaps two nodes of every tetrahedron with negative volume, so that all are positive.
void orient_positive(TetMesh& mesh) {
  for (int t = 0; t < mesh.tet_count(); ++t)
    if (signed_volume(mesh, t) < 0) std::swap(mesh.tets[t][2], mesh.tets[t][3]);
}

/// Box mesh with tags 500 + i and 100 + i instead of the mesher's index + 1.
TetMesh tagged_box(const Eigen::Vector3d& min_corner, double size, int divisions) {
  TetMesh mesh = make_box_mesh(min_corner, Eigen::Vector3d::Constant(size),
                               Eigen::Vector3i::Constant(divisions));
  for (int n = 0; n < mesh.node_count(); ++n) mesh.node_tags[n] = kNodeTagBase + n;
  for (int t = 0; t < mesh.tet_count(); ++t) mesh.tet_tags[t] = kTetTagBase + t;
  return mesh;
}

bool contains(const std::string& text, const std::string& fragment) {
  return text.find(fragment) != std::string::npos;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& line : lines) out += line + "\n";
  return out;
}

/// The mesh error check_tet_mesh throws, or "" if none.
std::string mesh_error(TetMesh mesh) {
  try {
    check_tet_mesh(mesh);
  } catch (const MeshError& e) {
    return e.what();
  }
  return "";
}

/// Interior dihedral angle at each of the six edges, computed independently of the library:
/// the angle between the two other vertices projected onto the plane normal to the edge.
double brute_min_dihedral_deg(const Eigen::Vector3d x[4]) {
  double smallest = 180;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      int others[2], m = 0;
      for (int k = 0; k < 4; ++k)
        if (k != i && k != j) others[m++] = k;
      const Eigen::Vector3d e = (x[j] - x[i]).normalized();
      Eigen::Vector3d u = x[others[0]] - x[i], v = x[others[1]] - x[i];
      u -= u.dot(e) * e;
      v -= v.dot(e) * e;
      const double angle = std::atan2(u.cross(v).norm(), u.dot(v)) * 180 / std::numbers::pi;
      smallest = std::min(smallest, angle);
    }
  return smallest;
}

TEST(MeshChecks, CleanBoxMeshHasNoFindings) {
  // Baseline for the tests below: each finding there is caused by the defect they add.
  TetMesh mesh = tagged_box(Eigen::Vector3d::Zero(), 1, 3);
  const MeshCheckReport report = check_tet_mesh(mesh);
  EXPECT_TRUE(report.warnings.empty()) << joined(report.warnings);
  EXPECT_TRUE(report.notes.empty()) << joined(report.notes);
  EXPECT_EQ(report.parts, 1);
  const BoundarySurface surface = extract_boundary_surface(mesh);
  EXPECT_TRUE(check_boundary_surface(mesh, surface).empty())
      << joined(check_boundary_surface(mesh, surface));
}

TEST(MeshChecks, OneInvertedElementIsAnErrorNamingItsTag) {
  TetMesh mesh = tagged_box(Eigen::Vector3d::Zero(), 1, 2);  // 48 tets, tags 100..147
  const int inverted = 17;
  std::swap(mesh.tets[inverted][0], mesh.tets[inverted][1]);
  ASSERT_LT(signed_volume(mesh, inverted), 0);
  const std::string message = mesh_error(mesh);
  EXPECT_TRUE(contains(message, "inverted")) << message;
  EXPECT_TRUE(contains(message, "element 117")) << message;
  EXPECT_TRUE(contains(message, "47 others")) << message;
  EXPECT_FALSE(contains(message, "element 100")) << message;
}

TEST(MeshChecks, AllNegativelyOrientedIsReorientedWithANote) {
  TetMesh mesh = tagged_box(Eigen::Vector3d(1, 2, 3), 2, 2);
  const TetMesh original = mesh;
  for (Tet& tet : mesh.tets) std::swap(tet[0], tet[3]);
  for (int t = 0; t < mesh.tet_count(); ++t) ASSERT_LT(signed_volume(mesh, t), 0);

  const MeshCheckReport report = check_tet_mesh(mesh);
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_TRUE(contains(report.notes[0], "reoriented")) << report.notes[0];
  EXPECT_TRUE(report.warnings.empty()) << joined(report.warnings);
  double volume = 0;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    EXPECT_GT(signed_volume(mesh, t), 0) << "tet " << t;
    EXPECT_NEAR(signed_volume(mesh, t), signed_volume(original, t), 1e-15) << "tet " << t;
    // Same node set: only the order changed.
    Tet a = mesh.tets[t], b = original.tets[t];
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b);
    volume += signed_volume(mesh, t);
  }
  EXPECT_NEAR(volume, 8.0, 1e-12);
}

TEST(MeshChecks, FlatElementIsAZeroVolumeErrorNamingItsTag) {
  // A good tetrahedron and, beside it, four coplanar points (z = 0) as a second element.
  const std::vector<Eigen::Vector3d> points{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1},
                                            {2, 0, 0}, {3, 0, 0}, {2, 1, 0}, {3, 1, 0}};
  TetMesh mesh = make_mesh(points, {{0, 1, 2, 3}, {4, 5, 6, 7}});
  ASSERT_GT(signed_volume(mesh, 0), 0);
  ASSERT_EQ(signed_volume(mesh, 1), 0);
  const std::string message = mesh_error(mesh);
  EXPECT_TRUE(contains(message, "zero-volume")) << message;
  EXPECT_TRUE(contains(message, "element 101")) << message;
  EXPECT_FALSE(contains(message, "element 100")) << message;
}

TEST(MeshChecks, CoincidentNodesWithDifferentTagsAreNamed) {
  // Two tetrahedra that should share the face (1, 2, 3); the second uses copies 4, 5 of
  // nodes 1 and 2, so the mesh is cracked along that face.
  const std::vector<Eigen::Vector3d> points{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1},
                                            {1, 0, 0}, {0, 1, 0}, {1, 1, 1}};
  TetMesh mesh = make_mesh(points, {{0, 1, 2, 3}, {4, 6, 5, 3}});
  orient_positive(mesh);
  const MeshCheckReport report = check_tet_mesh(mesh);
  const std::string all = joined(report.warnings);
  const auto coincident =
      std::find_if(report.warnings.begin(), report.warnings.end(),
                   [](const std::string& w) { return contains(w, "coincident"); });
  ASSERT_NE(coincident, report.warnings.end()) << all;
  EXPECT_TRUE(contains(*coincident, "2 pair(s)")) << *coincident;
  EXPECT_TRUE(contains(*coincident, "501 and 504")) << *coincident;
  EXPECT_TRUE(contains(*coincident, "502 and 505")) << *coincident;
  EXPECT_FALSE(contains(*coincident, "503")) << *coincident;
  // The crack also splits the mesh: the two elements share no face.
  EXPECT_EQ(report.parts, 2);
}

TEST(MeshChecks, TwoSeparateBoxesAreTwoParts) {
  const TetMesh a = tagged_box(Eigen::Vector3d::Zero(), 1, 2);
  const TetMesh b = tagged_box(Eigen::Vector3d(3, 0, 0), 1, 2);
  TetMesh mesh;
  mesh.nodes.resize(3, a.node_count() + b.node_count());
  mesh.nodes << a.nodes, b.nodes;
  mesh.tets = a.tets;
  for (Tet tet : b.tets) {
    for (int& v : tet) v += a.node_count();
    mesh.tets.push_back(tet);
  }
  for (int n = 0; n < mesh.node_count(); ++n) mesh.node_tags.push_back(kNodeTagBase + n);
  for (int t = 0; t < mesh.tet_count(); ++t) mesh.tet_tags.push_back(kTetTagBase + t);

  const MeshCheckReport report = check_tet_mesh(mesh);
  EXPECT_EQ(report.parts, 2);
  ASSERT_EQ(report.warnings.size(), 1u) << joined(report.warnings);
  EXPECT_TRUE(contains(report.warnings[0], "disconnected")) << report.warnings[0];
  EXPECT_TRUE(contains(report.warnings[0], "48 elements")) << report.warnings[0];

  // Still a valid closed surface: two boxes' worth of triangles, all manifold.
  const BoundarySurface surface = extract_boundary_surface(mesh);
  EXPECT_EQ(surface.triangle_count(), 2 * 6 * 2 * 2 * 2);
  EXPECT_TRUE(check_boundary_surface(mesh, surface).empty());
}

TEST(MeshCheckSurface, TetrahedraTouchingAtOneVertexMakeANonManifoldVertex) {
  const std::vector<Eigen::Vector3d> points{{0, 0, 0},  {1, 0, 0},  {0, 1, 0}, {0, 0, 1},
                                            {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
  TetMesh mesh = make_mesh(points, {{0, 1, 2, 3}, {0, 4, 5, 6}});
  orient_positive(mesh);
  const MeshCheckReport report = check_tet_mesh(mesh);
  EXPECT_EQ(report.parts, 2);  // no shared face

  const BoundarySurface surface = extract_boundary_surface(mesh);
  EXPECT_EQ(surface.triangle_count(), 8);
  const auto findings = check_boundary_surface(mesh, surface);
  ASSERT_EQ(findings.size(), 1u) << joined(findings);  // a vertex, no edge
  EXPECT_TRUE(contains(findings[0], "non-manifold surface vertex")) << findings[0];
  EXPECT_TRUE(contains(findings[0], "1 non-manifold")) << findings[0];
  EXPECT_TRUE(contains(findings[0], "node 500")) << findings[0];
}

TEST(MeshCheckSurface, TetrahedraTouchingAlongOneEdgeMakeANonManifoldEdge) {
  // Shared edge 0-1 on the x axis; the two elements lie in opposite quadrants around it.
  const std::vector<Eigen::Vector3d> points{{0, 0, 0}, {1, 0, 0},  {0, 1, 0},
                                            {0, 0, 1}, {0, -1, 0}, {0, 0, -1}};
  TetMesh mesh = make_mesh(points, {{0, 1, 2, 3}, {0, 1, 4, 5}});
  orient_positive(mesh);
  check_tet_mesh(mesh);
  const BoundarySurface surface = extract_boundary_surface(mesh);
  const auto findings = check_boundary_surface(mesh, surface);
  const std::string all = joined(findings);
  // Four surface triangles meet at this one edge: it is named once.
  EXPECT_TRUE(contains(all, "1 non-manifold surface edge")) << all;
  EXPECT_TRUE(contains(all, "500-501")) << all;
  EXPECT_FALSE(contains(all, "500-501, 500-501")) << all;
  // Both end nodes are also where two parts of the surface touch.
  EXPECT_TRUE(contains(
      all,
      "non-manifold surface vertex(es) (parts of the surface touch at a point): node 500, 501"))
      << all;
}

TEST(MeshChecks, SliverIsWarnedWithItsTag) {
  const double eps = 1e-3;
  // A unit square's corners with one lifted by eps: all four nearly coplanar.
  const std::vector<Eigen::Vector3d> points{
      {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, eps}, {0, 0, -2}};
  TetMesh mesh = make_mesh(points, {{0, 1, 2, 4}, {0, 1, 2, 3}});
  orient_positive(mesh);
  const Eigen::Vector3d x[4] = {mesh.nodes.col(mesh.tets[1][0]), mesh.nodes.col(mesh.tets[1][1]),
                                mesh.nodes.col(mesh.tets[1][2]), mesh.nodes.col(mesh.tets[1][3])};
  const double expected = brute_min_dihedral_deg(x);
  ASSERT_LT(expected, 1.0);
  EXPECT_NEAR(min_dihedral_angle_deg(mesh, 1), expected, 1e-9);

  const MeshCheckReport report = check_tet_mesh(mesh);
  const auto sliver = std::find_if(report.warnings.begin(), report.warnings.end(),
                                   [](const std::string& w) { return contains(w, "sliver"); });
  ASSERT_NE(sliver, report.warnings.end()) << joined(report.warnings);
  EXPECT_TRUE(contains(*sliver, "1 sliver")) << *sliver;
  EXPECT_TRUE(contains(*sliver, "element 101")) << *sliver;
  EXPECT_FALSE(contains(*sliver, "element 100")) << *sliver;
  EXPECT_NEAR(report.min_dihedral_deg, expected, 1e-9);
}

TEST(MeshChecks, DihedralAnglesOfRegularAndKuhnTetrahedra) {
  const std::vector<Eigen::Vector3d> regular{{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  TetMesh mesh = make_mesh(regular, {{0, 1, 2, 3}});
  orient_positive(mesh);
  EXPECT_NEAR(min_dihedral_angle_deg(mesh, 0), std::acos(1.0 / 3.0) * 180 / std::numbers::pi,
              1e-10);
  EXPECT_NEAR(min_dihedral_angle_deg(mesh, 0), 70.528779365509308, 1e-10);

  // Kuhn tetrahedra of a cube cell have dihedral angles 45, 60 and 90 degrees.
  TetMesh box = tagged_box(Eigen::Vector3d(-1, 0, 2), 0.3, 2);
  for (int t = 0; t < box.tet_count(); ++t)
    EXPECT_NEAR(min_dihedral_angle_deg(box, t), 45.0, 1e-10) << "tet " << t;
  EXPECT_NEAR(check_tet_mesh(box).min_dihedral_deg, 45.0, 1e-10);
}

TEST(MeshChecks, MinDihedralAngleMatchesBruteForceOnRandomTetrahedra) {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> coordinate(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 4; ++i)
      points.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
    TetMesh mesh = make_mesh(points, {{0, 1, 2, 3}});
    if (std::abs(signed_volume(mesh, 0)) < 1e-3) continue;
    const Eigen::Vector3d x[4] = {points[0], points[1], points[2], points[3]};
    EXPECT_NEAR(min_dihedral_angle_deg(mesh, 0), brute_min_dihedral_deg(x), 1e-7)
        << "trial " << trial;
    // Orientation does not matter for an angle.
    orient_positive(mesh);
    EXPECT_NEAR(min_dihedral_angle_deg(mesh, 0), brute_min_dihedral_deg(x), 1e-7)
        << "trial " << trial;
  }
}

TEST(MeshCheckSurface, FaceSharedByThreeTetrahedraIsAnError) {
  // Face (0, 1, 2) in the plane z = 0 with three apexes: one below, two above.
  const std::vector<Eigen::Vector3d> points{{0, 0, 0},      {1, 0, 0},     {0, 1, 0},
                                            {0.2, 0.2, -1}, {0.2, 0.2, 1}, {0.3, 0.1, 2}};
  TetMesh mesh = make_mesh(points, {{0, 1, 2, 3}, {0, 1, 2, 4}, {0, 1, 2, 5}});
  orient_positive(mesh);
  try {
    extract_boundary_surface(mesh);
    FAIL() << "no MeshError";
  } catch (const MeshError& e) {
    const std::string message = e.what();
    EXPECT_TRUE(contains(message, "more than two")) << message;
    for (const char* tag : {"500", "501", "502"}) EXPECT_TRUE(contains(message, tag)) << message;
    EXPECT_TRUE(contains(message, "element 102")) << message;  // the third one to use the face
  }
}

TEST(MeshCheckSurface, TriangleSurfaceOpenAndClosed) {
  TriangleSurface single;
  single.vertices.resize(3, 3);
  single.vertices << 0, 1, 0, 0, 0, 1, 0, 0, 0;
  single.triangles = {{0, 1, 2}};
  const auto open = check_triangle_surface(single, "lid");
  ASSERT_EQ(open.size(), 1u) << joined(open);
  EXPECT_TRUE(contains(open[0], "lid")) << open[0];
  EXPECT_TRUE(contains(open[0], "open surface")) << open[0];
  EXPECT_TRUE(contains(open[0], "3 boundary edge")) << open[0];
  for (const char* edge : {"0-1", "0-2", "1-2"}) EXPECT_TRUE(contains(open[0], edge)) << open[0];

  TriangleSurface closed;
  closed.vertices.resize(3, 4);
  closed.vertices << 0, 1, 0, 0,  //
      0, 0, 1, 0,                 //
      0, 0, 0, 1;
  closed.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  EXPECT_TRUE(check_triangle_surface(closed, "tetrahedron").empty())
      << joined(check_triangle_surface(closed, "t"));

  // A fin on the closed surface: edge 0-1 then has three triangles.
  TriangleSurface fin = closed;
  fin.vertices.conservativeResize(3, 5);
  fin.vertices.col(4) = Eigen::Vector3d(0.5, -1, 0);
  fin.triangles.push_back({0, 1, 4});
  const auto fin_findings = check_triangle_surface(fin, "fin");
  const std::string all = joined(fin_findings);
  EXPECT_TRUE(contains(all, "1 non-manifold edge(s) between vertices 0-1")) << all;
  EXPECT_TRUE(contains(all, "2 boundary edge(s)")) << all;  // 0-4 and 1-4
}

}  // namespace
}  // namespace cohaptic
