// The home-spring force model (common/laparoscopy/home_spring_*.h), the laparoscopy
// paper's Eq. 8, against independent answers: the closed form of a vertex pressed
// straight into a flat regular hexagonal 1-ring, the potential it derives from (closed
// loops do no work, finite differences of the energy give the force), and Eq. 8 written
// out again here, with neighbours found by distance and the contact by a line-plane
// intersection, on random pokes of a sheet; plus the patch's validation messages.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "common/laparoscopy/extract_home_spring_patch.h"
#include "common/laparoscopy/home_spring_contact.h"
#include "common/laparoscopy/home_spring_force.h"
#include "common/util/error.h"
#include "support/tissue_sheet.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;

constexpr double kHome = 300;       // k1 [N/m]
constexpr double kNeighbour = 120;  // k2 [N/m]

/// Vertex 0 at `centre`, its six neighbours at distance h in the plane z = 0 (optionally
/// jittered in 3-D by up to `jitter`), one triangle per sector.
HomeSpringPatch hexagon(double h, double jitter = 0, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> noise(-jitter, jitter);
  HomeSpringPatch patch;
  patch.rest_positions.resize(3, 7);
  patch.rest_positions.col(0).setZero();
  for (int j = 0; j < 6; ++j) {
    const double angle = j * std::numbers::pi / 3;
    patch.rest_positions.col(j + 1) = Vector3d(h * std::cos(angle), h * std::sin(angle), 0) +
                                      Vector3d(noise(rng), noise(rng), noise(rng));
  }
  patch.contact_vertex_count = 1;
  patch.ring_offsets = {0, 6};
  patch.ring_vertices = {1, 2, 3, 4, 5, 6};
  patch.surface_vertex = {0, 1, 2, 3, 4, 5, 6};
  patch.home_stiffness = kHome;
  patch.neighbour_stiffness = kNeighbour;
  patch.trocar_pivot = Vector3d(0, 0, 0.1);
  return patch;
}

/// A patch that validates needs a triangle of touchable vertices: make the ring touchable.
HomeSpringPatch touchable_hexagon(double h) {
  HomeSpringPatch patch = hexagon(h);
  const VertexRings rings = vertex_rings(
      std::vector<Triangle>{{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}, {0, 5, 6}, {0, 6, 1}}, 7);
  patch.contact_vertex_count = 7;
  patch.ring_offsets = rings.offsets;
  patch.ring_vertices = rings.vertices;
  patch.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}, {0, 5, 6}, {0, 6, 1}};
  return patch;
}

TEST(HomeSprings, FlatHexagonNormalForceClosedForm) {
  const double h = 0.004;
  const HomeSpringPatch patch = hexagon(h);
  for (const double delta : {1e-5, 1e-4, 1e-3, 3e-3, 1e-2, -2e-3}) {
    const Vector3d load = home_spring_load(patch, 0, Vector3d(0, 0, -delta));
    const double expected =
        kHome * delta + 6 * kNeighbour * delta * (1 - h / std::sqrt(h * h + delta * delta));
    EXPECT_NEAR(-load.z(), expected, 1e-12 * std::abs(expected)) << "delta " << delta;
    EXPECT_NEAR(load.x(), 0, 1e-12 * std::abs(expected));
    EXPECT_NEAR(load.y(), 0, 1e-12 * std::abs(expected));
  }
}

TEST(HomeSprings, IndentationStiffnessIsTheHomeSpring) {
  // The ring springs are perpendicular to a normal indentation: to first order only k1 acts.
  const HomeSpringPatch patch = hexagon(0.004);
  const double step = 1e-7;
  const double stiffness = (home_spring_load(patch, 0, Vector3d(0, 0, step)).z() -
                            home_spring_load(patch, 0, Vector3d(0, 0, -step)).z()) /
                           (2 * step);
  EXPECT_NEAR(stiffness, kHome, 1e-9 * kHome);
  // In the plane, each ring spring adds k2 cos^2 of its angle: 3 k2 in every direction.
  const double shear = (home_spring_load(patch, 0, Vector3d(step, 0, 0)).x() -
                        home_spring_load(patch, 0, Vector3d(-step, 0, 0)).x()) /
                       (2 * step);
  EXPECT_NEAR(shear, kHome + 3 * kNeighbour, 1e-6 * kHome);
}

TEST(HomeSprings, LoadIsTheEnergyGradient) {
  const HomeSpringPatch patch = hexagon(0.004, 0.001, 7);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-0.006, 0.006);
  const double step = 1e-7;
  for (int trial = 0; trial < 200; ++trial) {
    const Vector3d u(coordinate(rng), coordinate(rng), coordinate(rng));
    Vector3d gradient;
    for (int axis = 0; axis < 3; ++axis) {
      const Vector3d e = step * Vector3d::Unit(axis);
      gradient[axis] =
          (home_spring_energy(patch, 0, u + e) - home_spring_energy(patch, 0, u - e)) / (2 * step);
    }
    const Vector3d load = home_spring_load(patch, 0, u);
    EXPECT_LT((gradient - load).norm(), 1e-6 * load.norm()) << "u " << u.transpose();
  }
}

TEST(HomeSprings, ClosedLoopsDoNoWork) {
  // A smooth periodic loop, integrated by the trapezoid rule (spectrally accurate for a
  // periodic integrand): the work must vanish; along the open half it must equal the
  // energy difference.
  const HomeSpringPatch patch = hexagon(0.004, 0.001, 11);
  const Vector3d centre(0.001, -0.0005, -0.003);
  const auto loop = [&](double s) {
    return Vector3d(centre.x() + 0.004 * std::cos(s), centre.y() + 0.003 * std::sin(s),
                    centre.z() + 0.002 * std::sin(2 * s));
  };
  const auto tangent = [&](double s) {
    return Vector3d(-0.004 * std::sin(s), 0.003 * std::cos(s), 0.004 * std::cos(2 * s));
  };
  const int n = 4000;
  const double ds = 2 * std::numbers::pi / n;
  double work = 0, scale = 0;
  for (int i = 0; i < n; ++i) {
    const double s = i * ds;
    const double power = home_spring_load(patch, 0, loop(s)).dot(tangent(s));
    work += power * ds;
    scale += std::abs(power) * ds;
  }
  EXPECT_LT(std::abs(work), 1e-9) << "scale of |work| " << scale << " J";
  EXPECT_GT(scale, 1e-4);  // the loop does meet the springs

  // Half the loop by Gauss-free composite Simpson against E(end) - E(start).
  const int half = 2000;
  const double h = std::numbers::pi / half;
  double open = 0;
  for (int i = 0; i <= half; ++i) {
    const double weight = (i == 0 || i == half) ? 1 : (i % 2 ? 4 : 2);
    open += weight * home_spring_load(patch, 0, loop(i * h)).dot(tangent(i * h));
  }
  open *= h / 3;
  const double difference =
      home_spring_energy(patch, 0, loop(std::numbers::pi)) - home_spring_energy(patch, 0, loop(0));
  EXPECT_NEAR(open, difference, 1e-9);
}

TEST(HomeSprings, NeighbourOnTheVertexAddsNothingUndefined) {
  const HomeSpringPatch patch = hexagon(0.004);
  const Vector3d onto_neighbour = patch.rest_positions.col(1);  // L_1 = 0
  const Vector3d load = home_spring_load(patch, 0, onto_neighbour);
  EXPECT_TRUE(load.allFinite());
}

/// Eq. 8 written out from the paper, independently of the patch's rings: the neighbours of
/// the sheet vertex nearest the contact are the vertices at one spacing from it.
Vector3d independent_eq8(const TriangleSurface& sheet, double spacing, int vertex,
                         const Vector3d& current) {
  const Vector3d original = sheet.vertices.col(vertex);
  Vector3d total = kHome * (current - original);
  for (int j = 0; j < sheet.vertex_count(); ++j) {
    const double d = (sheet.vertices.col(j) - original).norm();
    if (j == vertex || std::abs(d - spacing) > 1e-9 * spacing) continue;
    const Vector3d link = current - sheet.vertices.col(j);
    total += kNeighbour * (link.norm() - d) * link / link.norm();
  }
  return total;
}

TEST(HomeSprings, RandomPokesMatchEq8WrittenOut) {
  const double spacing = 0.003;
  const TriangleSurface sheet = testing::equilateral_sheet(30, 30, spacing);
  const VertexRings rings = vertex_rings(sheet.triangles, sheet.vertex_count());
  const Vector3d pivot(0.01, -0.02, 0.12);
  const PreparedHomeSpringPatch prepared = prepare_home_spring_patch(
      extract_home_spring_patch({sheet.vertices, sheet.triangles, rings}, Vector3d::Zero(), 0.02,
                                {kHome, kNeighbour}, pivot));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> across(-0.015, 0.015), depth(-0.008, 0.004);
  int touching = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Vector3d tool(across(rng), across(rng), depth(rng));
    const HomeSpringContact contact = evaluate_home_spring(prepared, tool);
    // Independent: where the line pivot -> tool meets z = 0, if between them.
    const double t = pivot.z() / (pivot.z() - tool.z());
    if (tool.z() > 0) {
      EXPECT_FALSE(contact.touching) << "tool above the sheet at " << tool.transpose();
      continue;
    }
    const Vector3d p = pivot + t * (tool - pivot);
    if (p.head<2>().norm() > 0.0155) continue;  // near the patch's rim: coverage differs
    int nearest = 0;
    for (int v = 1; v < sheet.vertex_count(); ++v)
      if ((sheet.vertices.col(v) - p).squaredNorm() <
          (sheet.vertices.col(nearest) - p).squaredNorm())
        nearest = v;
    ASSERT_TRUE(contact.touching) << "tool " << tool.transpose();
    ++touching;
    EXPECT_EQ(prepared.patch.surface_vertex[static_cast<std::size_t>(contact.vertex)], nearest);
    EXPECT_LT((contact.contact_point - p).norm(), 1e-12);
    const Vector3d expected =
        -independent_eq8(sheet, spacing, nearest, sheet.vertices.col(nearest) + (tool - p));
    EXPECT_LT((contact.force - expected).norm(), 1e-12 * (1 + expected.norm()))
        << "tool " << tool.transpose();
  }
  EXPECT_GT(touching, 500);
}

TEST(HomeSprings, GraspedVertexFollowsTheTool) {
  HomeSpringPatch patch = touchable_hexagon(0.004);
  patch.grasp = {0, Vector3d(0.001, 0, 0.002)};
  const PreparedHomeSpringPatch prepared = prepare_home_spring_patch(patch);
  const HomeSpringContact at_grasp = evaluate_home_spring(prepared, patch.grasp.tool_at_grasp);
  EXPECT_TRUE(at_grasp.touching);
  EXPECT_EQ(at_grasp.force, Vector3d::Zero());
  const Vector3d pulled =
      patch.grasp.tool_at_grasp + Vector3d(0, 0, 0.005);  // well above the surface
  const HomeSpringContact pull = evaluate_home_spring(prepared, pulled);
  EXPECT_EQ(pull.vertex, 0);
  const double h = 0.004, delta = 0.005;
  EXPECT_NEAR(
      pull.force.z(),
      -(kHome * delta + 6 * kNeighbour * delta * (1 - h / std::sqrt(h * h + delta * delta))),
      1e-12);
}

TEST(HomeSprings, ToolThatIsNotFiniteTouchesNothing) {
  const PreparedHomeSpringPatch prepared = prepare_home_spring_patch(touchable_hexagon(0.004));
  const HomeSpringContact contact =
      evaluate_home_spring(prepared, Vector3d(0, std::nan(""), -0.001));
  EXPECT_FALSE(contact.touching);
  EXPECT_EQ(contact.force, Vector3d::Zero());
  EXPECT_TRUE(evaluate_home_spring(prepared, Vector3d(0.0005, 0.0003, -0.001)).touching);
}

void expect_rejected(const HomeSpringPatch& patch, const std::string& fragment) {
  try {
    validate_home_spring_patch(patch);
    ADD_FAILURE() << "accepted; expected an error containing \"" << fragment << "\"";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(HomeSprings, ValidationNamesWhatIsWrong) {
  const HomeSpringPatch good = touchable_hexagon(0.004);
  EXPECT_NO_THROW(validate_home_spring_patch(good));
  HomeSpringPatch p = good;
  p.home_stiffness = 0;
  expect_rejected(p, "home_stiffness (k1) is 0");
  p = good;
  p.neighbour_stiffness = -1;
  expect_rejected(p, "neighbour_stiffness (k2) is -1");
  p = good;
  p.rest_positions(2, 3) = std::nan("");
  expect_rejected(p, "rest position of vertex 3 is not finite");
  p = good;
  p.ring_vertices[2] = 0;
  expect_rejected(p, "vertex 0 is in its own 1-ring");
  p = good;
  p.ring_vertices[1] = p.ring_vertices[0];
  expect_rejected(p, "names vertex 1 twice");
  p = good;
  p.ring_vertices[0] = 9;
  expect_rejected(p, "names vertex 9, but there are 7 vertices");
  p = good;
  p.ring_offsets.pop_back();
  expect_rejected(p, "ring_offsets has 7 entries, expected contact_vertex_count + 1 = 8");
  p = good;
  p.ring_offsets[1] = 1000;  // a ring past ring_vertices, caught before it is read
  expect_rejected(p, "ring_offsets decrease at vertex 1");
  p = good;
  p.triangles[4] = {0, 5, 5};
  expect_rejected(p, "triangle 4 is degenerate");
  p = good;
  p.contact_vertex_count = 3;
  p.ring_offsets.resize(4);
  p.ring_vertices.resize(static_cast<std::size_t>(p.ring_offsets.back()));
  expect_rejected(p, "triangle 1 names vertex 3, but only vertices 0..2 may be touched");
  p = good;
  p.grasp.vertex = 7;
  expect_rejected(p, "grasp names vertex 7");
  p = good;
  p.surface_vertex[5] = 2;
  expect_rejected(p, "surface vertex 2 appears twice");
  p = good;
  p.rest_positions.col(4) = p.rest_positions.col(0);
  expect_rejected(p, "is at its rest position");
  EXPECT_THROW(prepare_home_spring_patch(hexagon(0.004)), Error);  // no triangle
}

TEST(HomeSprings, ExtractedPatchHasFullRings) {
  const TriangleSurface sheet = testing::equilateral_sheet(20, 20, 0.003);
  const VertexRings rings = vertex_rings(sheet.triangles, sheet.vertex_count());
  const HomeSpringPatch patch =
      extract_home_spring_patch({sheet.vertices, sheet.triangles, rings}, Vector3d::Zero(), 0.01,
                                {kHome, kNeighbour}, Vector3d(0, 0, 0.1));
  EXPECT_GT(patch.contact_vertex_count, 30);
  for (int v = 0; v < patch.contact_vertex_count; ++v) {
    EXPECT_EQ(patch.ring(v).size(), 6u) << "vertex " << v;  // interior of the sheet: hexagons
    for (const int j : patch.ring(v))
      EXPECT_NEAR((patch.rest_positions.col(j) - patch.rest_positions.col(v)).norm(), 0.003, 1e-12);
  }
  EXPECT_GT(patch.vertex_count(), patch.contact_vertex_count);  // ring-only rim
  EXPECT_THROW(
      extract_home_spring_patch({sheet.vertices, sheet.triangles, rings}, Vector3d(1, 1, 1), 0.01,
                                {kHome, kNeighbour}, Vector3d::Zero()),
      Error);
}

}  // namespace
}  // namespace cohaptic
