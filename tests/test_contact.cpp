// Contact geometry (common/contact): closest point on a triangle against brute force and
// a second exact method, signed distance to a box mesh against the analytic box
// distance, and find_contact on the box's top face against hand computations.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "common/contact/closest_point_on_triangle.h"
#include "common/contact/find_contact.h"
#include "common/contact/surface_distance.h"
#include "common/mesh/boundary_surface.h"
#include "common/mesh/box_mesher.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;

/// Closest point on segment [s, e] (a point if s == e).
Vector3d closest_on_segment(const Vector3d& p, const Vector3d& s, const Vector3d& e) {
  const double length2 = (e - s).squaredNorm();
  if (length2 == 0) return s;
  return s + std::clamp((p - s).dot(e - s) / length2, 0.0, 1.0) * (e - s);
}

/// A second exact method: the projection onto the plane if it falls inside (by signs of
/// sub-triangle normals), else the best of the three edges.
double exact_distance(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d n = (b - a).cross(c - a);
  if (n.squaredNorm() > 0) {
    const Vector3d q = p - (p - a).dot(n) / n.squaredNorm() * n;
    if ((b - a).cross(q - a).dot(n) >= 0 && (c - b).cross(q - b).dot(n) >= 0 &&
        (a - c).cross(q - c).dot(n) >= 0)
      return (p - q).norm();
  }
  return std::min({(p - closest_on_segment(p, a, b)).norm(),
                   (p - closest_on_segment(p, b, c)).norm(),
                   (p - closest_on_segment(p, c, a)).norm()});
}

/// Distance to the nearest of the (N+1)(N+2)/2 points of a barycentric grid, and the
/// grid's resolution (no point of the triangle is farther than that from a sample).
struct BruteForce {
  double distance;
  double resolution;
};
BruteForce brute_force_distance(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                                const Vector3d& c, int n) {
  double best2 = std::numeric_limits<double>::infinity();
  const Vector3d ab = (b - a) / n, ac = (c - a) / n;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j)
      best2 = std::min(best2, (a + i * ab + j * ac - p).squaredNorm());
  const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
  return {std::sqrt(best2), longest / n};
}

void expect_valid_weights(const TriangleClosestPoint& q, const Vector3d& a, const Vector3d& b,
                          const Vector3d& c) {
  EXPECT_GE(q.weights.minCoeff(), 0.0) << q.weights.transpose();
  EXPECT_NEAR(q.weights.sum(), 1.0, 1e-12);
  const Vector3d rebuilt = q.weights[0] * a + q.weights[1] * b + q.weights[2] * c;
  EXPECT_LT((rebuilt - q.point).norm(), 1e-12 * std::max(1.0, q.point.norm()));
}

TEST(ClosestPointOnTriangle, MatchesBruteForceAndExactReferenceOnRandomTriangles) {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> vertex(-1, 1), point(-2, 2);
  constexpr int kSamples = 200;
  for (int trial = 0; trial < 300; ++trial) {
    const Vector3d a(vertex(rng), vertex(rng), vertex(rng));
    const Vector3d b(vertex(rng), vertex(rng), vertex(rng));
    const Vector3d c(vertex(rng), vertex(rng), vertex(rng));
    // Half of the points near the triangle's plane, where the face interior wins more often.
    Vector3d p(point(rng), point(rng), point(rng));
    if (trial % 2 == 0) {
      const Vector3d n = (b - a).cross(c - a).normalized();
      p = (a + b + c) / 3 + (p - (a + b + c) / 3).dot(n) * 0.1 * n +
          0.8 * (p - (p - a).dot(n) * n - a);
    }
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    const TriangleClosestPoint q = closest_point_on_triangle(p, a, b, c);
    expect_valid_weights(q, a, b, c);
    const double distance = (p - q.point).norm();
    const BruteForce brute = brute_force_distance(p, a, b, c, kSamples);
    EXPECT_LE(distance, brute.distance + 1e-12);
    EXPECT_GE(distance, brute.distance - brute.resolution);
    EXPECT_NEAR(distance, exact_distance(p, a, b, c), 1e-12);
  }
}

TEST(ClosestPointOnTriangle, ZeroWeightPatternNamesTheFeature) {
  const Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  struct Case {
    Vector3d p;
    Vector3d expected_point;
    Vector3d expected_weights;
  };
  const Case cases[] = {
      {{-1, -1, 0.5}, a, {1, 0, 0}},                     // vertex a
      {{2, -0.5, 1}, b, {0, 1, 0}},                      // vertex b
      {{-0.3, 2, -1}, c, {0, 0, 1}},                     // vertex c
      {{0.3, -1, 2}, {0.3, 0, 0}, {0.7, 0.3, 0}},        // edge ab
      {{-1, 0.6, 0}, {0, 0.6, 0}, {0.4, 0, 0.6}},        // edge ca
      {{1, 1, 0.7}, {0.5, 0.5, 0}, {0, 0.5, 0.5}},       // edge bc
      {{0.2, 0.3, 5}, {0.2, 0.3, 0}, {0.5, 0.2, 0.3}},   // face
      {{0.2, 0.3, -5}, {0.2, 0.3, 0}, {0.5, 0.2, 0.3}},  // face, other side
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(::testing::Message() << "p = " << k.p.transpose());
    const TriangleClosestPoint q = closest_point_on_triangle(k.p, a, b, c);
    EXPECT_LT((q.point - k.expected_point).norm(), 1e-15);
    for (int i = 0; i < 3; ++i) {
      if (k.expected_weights[i] == 0)
        EXPECT_EQ(q.weights[i], 0.0)
            << "weight " << i << " must be exactly zero: " << q.weights.transpose();
      else
        EXPECT_NEAR(q.weights[i], k.expected_weights[i], 1e-15) << "weight " << i;
    }
  }
}

TEST(ClosestPointOnTriangle, DegenerateTrianglesGiveAPointOnTheirSegment) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coordinate(-2, 2);
  // Collinear (c between a and b, or beyond), and with two coincident vertices.
  const Vector3d a(0, 0, 0), b(2, 1, -1);
  const Vector3d triangles[][3] = {{a, b, 0.5 * b}, {a, 0.5 * b, b}, {a, a, b}, {b, a, a}};
  for (const auto& tri : triangles) {
    // The segment the degenerate triangle spans: between its two farthest-apart vertices.
    Vector3d s = tri[0], e = tri[1];
    for (int i = 0; i < 3; ++i)
      for (int j = i + 1; j < 3; ++j)
        if ((tri[i] - tri[j]).norm() > (s - e).norm()) s = tri[i], e = tri[j];
    for (int trial = 0; trial < 50; ++trial) {
      const Vector3d p(coordinate(rng), coordinate(rng), coordinate(rng));
      const TriangleClosestPoint q = closest_point_on_triangle(p, tri[0], tri[1], tri[2]);
      ASSERT_TRUE(q.point.allFinite() && q.weights.allFinite());
      expect_valid_weights(q, tri[0], tri[1], tri[2]);
      const Vector3d expected = closest_on_segment(p, s, e);
      EXPECT_LT((q.point - expected).norm(), 1e-12)
          << "p " << p.transpose() << " got " << q.point.transpose();
    }
  }
  // All three vertices coincident.
  const TriangleClosestPoint q = closest_point_on_triangle(Vector3d(1, 2, 3), b, b, b);
  EXPECT_EQ(q.point, b);
  EXPECT_NEAR(q.weights.sum(), 1.0, 0.0);
}

// An exactly collinear triangle whose area terms come out as rounding noise (~1e-16, not
// 0): the closest point must still be the one on its edges, with a zero weight.
TEST(ClosestPointOnTriangle, ExactlyCollinearTriangleWithRoundingNoiseInItsAreaTerms) {
  const Vector3d a(0.5, 0.25, -0.25), b(0, 0, 0),
      c(3, 1.5, -1.5);                                // 0.25 d, 0, 1.5 d with d = (2, 1, -1)
  ASSERT_EQ((b - a).cross(c - a), Vector3d::Zero());  // exactly zero area
  const Vector3d p(1.6307384325554901, -1.2571786693070988, 0.58082513594345864);
  const Vector3d expected = closest_on_segment(p, b, c);  // (0.4745, 0.2372, -0.2372)
  const TriangleClosestPoint q = closest_point_on_triangle(p, a, b, c);
  ASSERT_TRUE(q.point.allFinite());
  EXPECT_LT((q.point - expected).norm(), 1e-12)
      << "got " << q.point.transpose() << ", expected " << expected.transpose() << ", weights "
      << q.weights.transpose();
  EXPECT_TRUE(q.weights.minCoeff() == 0)
      << "a point on a segment has a zero weight: " << q.weights.transpose();
}

// The unit box [0,1]^3 meshed with 3 divisions, its surface and pseudo-normals.
struct BoxFixture {
  TetMesh mesh = make_box_mesh(Vector3d::Zero(), Vector3d::Ones(), Eigen::Vector3i::Constant(3));
  BoundarySurface surface = extract_boundary_surface(mesh);
  SurfacePseudoNormals normals = compute_pseudo_normals(mesh, surface);
  std::vector<int> top;  // surface triangles of the face z = 1, selected by their normal

  BoxFixture() {
    for (int t = 0; t < surface.triangle_count(); ++t)
      if (normals.face[t].z() > 1 - 1e-12) top.push_back(t);
  }
};

/// Analytic signed distance to the box [0,1]^3: negative inside, positive outside.
double box_signed_distance(const Vector3d& p) {
  const Vector3d d = (p.array() - 0.5).abs() - 0.5;
  return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
}

TEST(ContactSignedDistance, MatchesAnalyticBoxDistance) {
  const BoxFixture box;
  std::vector<Vector3d> points;
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> anywhere(-0.5, 1.5), inside(0.001, 0.999),
      small(0.001, 0.2);
  for (int i = 0; i < 300; ++i) points.emplace_back(anywhere(rng), anywhere(rng), anywhere(rng));
  for (int i = 0; i < 100; ++i) points.emplace_back(inside(rng), inside(rng), inside(rng));
  // Outside near edges (closest point on a box edge) and corners (closest point a corner),
  // including edge points that are mesh vertices (x = 1/3, 2/3 on the edge y = z = 1).
  for (int i = 0; i < 100; ++i) {
    points.emplace_back(inside(rng), 1 + small(rng), 1 + small(rng));
    points.emplace_back(-small(rng), inside(rng), 1 + small(rng));
    points.emplace_back(1 + small(rng), -small(rng), inside(rng));
    points.emplace_back(1 + small(rng), 1 + small(rng), -small(rng));
    points.emplace_back(-small(rng), -small(rng), -small(rng));
  }
  points.emplace_back(1.0 / 3, 1.1, 1.05);
  points.emplace_back(2.0 / 3, 1.05, 1.1);
  // Inside near edges and corners, and on the bisecting planes of an edge.
  for (int i = 0; i < 50; ++i) {
    points.emplace_back(inside(rng), 1 - 0.1 * small(rng), 1 - 0.1 * small(rng));
    points.emplace_back(0.1 * small(rng), 0.1 * small(rng), 0.1 * small(rng));
    const double s = 0.3 * small(rng);
    points.emplace_back(inside(rng), s, s);
  }

  for (const Vector3d& p : points) {
    const SurfacePoint closest = closest_surface_point(box.mesh, box.surface, box.normals, p);
    const double expected = box_signed_distance(p);
    ASSERT_GE(closest.triangle, 0);
    EXPECT_NEAR(closest.signed_distance, expected, 1e-12) << "p = " << p.transpose();
    if (expected > 0) {
      const Vector3d foot = p.cwiseMax(0.0).cwiseMin(1.0);
      EXPECT_LT((closest.closest.point - foot).norm(), 1e-12) << "p = " << p.transpose();
    }
  }
}

TEST(ContactFind, TopFaceTrianglesAreTheTouchableSet) {
  const BoxFixture box;
  ASSERT_EQ(box.top.size(), 2u * 3 * 3);
  for (int t : box.top)
    for (int v : box.surface.triangles[t]) EXPECT_EQ(box.mesh.nodes(2, v), 1.0);
}

TEST(ContactFind, PointBelowTheTouchableFace) {
  const BoxFixture box;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> across(0.15, 0.85);
  std::vector<Vector3d> points{{0.5, 0.5, 0.9}};
  for (int i = 0; i < 100; ++i) points.emplace_back(across(rng), across(rng), 0.9);
  for (const Vector3d& p : points) {
    SCOPED_TRACE(::testing::Message() << "p = " << p.transpose());
    // The side faces are at least 0.15 away: the top face, 0.1 above, is the closest.
    const ContactQuery query = find_contact(box.mesh, box.surface, box.normals, box.top, p, 0);
    EXPECT_NEAR(query.signed_distance, -0.1, 1e-12);
    ASSERT_TRUE(query.contact.has_value());
    const ToolContact& contact = *query.contact;
    ASSERT_NE(std::find(box.top.begin(), box.top.end(), contact.triangle), box.top.end());
    EXPECT_LT((contact.foot - Vector3d(p.x(), p.y(), 1)).norm(), 1e-12);
    EXPECT_LT((contact.displacement - Vector3d(0, 0, -0.1)).norm(), 1e-12);
    EXPECT_NEAR(contact.depth, 0.1, 1e-12);
    // The triangle contains the foot: its area coordinates rebuild it and are >= 0.
    const Triangle& tri = box.surface.triangles[contact.triangle];
    expect_valid_weights({contact.foot, contact.weights}, box.mesh.nodes.col(tri[0]),
                         box.mesh.nodes.col(tri[1]), box.mesh.nodes.col(tri[2]));
  }
}

TEST(ContactFind, PointOutsideIsNoContact) {
  const BoxFixture box;
  for (const Vector3d& p :
       {Vector3d(0.5, 0.5, 1.1), Vector3d(0.3, 0.7, 1 + 1e-9), Vector3d(-0.1, 0.5, 0.5),
        Vector3d(0.5, 0.5, -0.01), Vector3d(1.05, 1.05, 1.05)}) {
    const ContactQuery query = find_contact(box.mesh, box.surface, box.normals, box.top, p, 0);
    EXPECT_FALSE(query.contact.has_value()) << "p = " << p.transpose();
    EXPECT_NEAR(query.signed_distance, box_signed_distance(p), 1e-12) << "p = " << p.transpose();
  }
  // Inside, but nothing touchable.
  const ContactQuery none =
      find_contact(box.mesh, box.surface, box.normals, {}, Vector3d(0.5, 0.5, 0.9), 0);
  EXPECT_FALSE(none.contact.has_value());
  EXPECT_NEAR(none.signed_distance, -0.1, 1e-12);
}

TEST(ContactFind, DeepUnderANonTouchableFaceStillPressesTheClosestTouchableTriangle) {
  // Documented behaviour: contact is decided by the signed distance to the WHOLE surface
  // (here -0.05, from the face x = 0, which is not touchable); the contact triangle is the
  // closest touchable one, on the top face 0.5 away, and depth and displacement both refer
  // to that triangle: d = (0, 0, -0.5), depth = -d . n = 0.5.
  const BoxFixture box;
  const Vector3d p(0.05, 0.5, 0.5);
  const ContactQuery query = find_contact(box.mesh, box.surface, box.normals, box.top, p, 0);
  EXPECT_NEAR(query.signed_distance, -0.05, 1e-12);
  ASSERT_TRUE(query.contact.has_value());
  const ToolContact& contact = *query.contact;
  EXPECT_NE(std::find(box.top.begin(), box.top.end(), contact.triangle), box.top.end());
  EXPECT_LT((contact.foot - Vector3d(0.05, 0.5, 1)).norm(), 1e-12);
  EXPECT_LT((contact.displacement - Vector3d(0, 0, -0.5)).norm(), 1e-12);
  EXPECT_NEAR(contact.depth, 0.5, 1e-12);
}

TEST(ContactFind, BelowASharedEdgeEitherTriangleDeterministically) {
  const BoxFixture box;
  const auto is_top = [&](int t) {
    return std::find(box.top.begin(), box.top.end(), t) != box.top.end();
  };
  int shared_edges = 0;
  for (int t : box.top)
    for (int k = 0; k < 3; ++k) {
      const int neighbour = box.surface.triangle_neighbours[t][k];
      if (neighbour < 0 || !is_top(neighbour) || neighbour < t)
        continue;  // each interior edge once
      ++shared_edges;
      const Triangle& tri = box.surface.triangles[t];
      const Vector3d midpoint =
          0.5 * (box.mesh.nodes.col(tri[k]) + box.mesh.nodes.col(tri[(k + 1) % 3]));
      const Vector3d p = midpoint - Vector3d(0, 0, 0.1);
      SCOPED_TRACE(::testing::Message() << "edge midpoint " << midpoint.transpose());
      const ContactQuery first = find_contact(box.mesh, box.surface, box.normals, box.top, p, 0);
      ASSERT_TRUE(first.contact.has_value());
      EXPECT_TRUE(first.contact->triangle == t || first.contact->triangle == neighbour)
          << first.contact->triangle;
      EXPECT_LT((first.contact->foot - midpoint).norm(), 1e-12);
      EXPECT_LT((first.contact->displacement - Vector3d(0, 0, -0.1)).norm(), 1e-12);
      EXPECT_NEAR(first.contact->depth, 0.1, 1e-12);
      // The foot is on the shared edge: the weight of the chosen triangle's third vertex
      // vanishes (to round-off: the computed midpoint need not lie exactly on the edge, so
      // an exact zero is not guaranteed here; see ZeroWeightPatternNamesTheFeature).
      const Triangle& chosen = box.surface.triangles[first.contact->triangle];
      for (int i = 0; i < 3; ++i) {
        if (chosen[i] != tri[k] && chosen[i] != tri[(k + 1) % 3]) {
          EXPECT_LT(first.contact->weights[i], 1e-15) << first.contact->weights.transpose();
        }
      }
      for (int repeat = 0; repeat < 3; ++repeat) {
        const ContactQuery again = find_contact(box.mesh, box.surface, box.normals, box.top, p, 0);
        ASSERT_TRUE(again.contact.has_value());
        EXPECT_EQ(again.contact->triangle, first.contact->triangle);
        EXPECT_EQ(again.contact->foot, first.contact->foot);
        EXPECT_EQ(again.contact->weights, first.contact->weights);
      }
      // Whichever order the candidates come in, the contact is physically the same.
      std::vector<int> reversed(box.top.rbegin(), box.top.rend());
      const ContactQuery other = find_contact(box.mesh, box.surface, box.normals, reversed, p, 0);
      ASSERT_TRUE(other.contact.has_value());
      EXPECT_TRUE(other.contact->triangle == t || other.contact->triangle == neighbour);
      EXPECT_LT((other.contact->foot - first.contact->foot).norm(), 1e-12);
      EXPECT_LT((other.contact->displacement - first.contact->displacement).norm(), 1e-12);
    }
  // A 3x3 grid of cells, two triangles each: 9 diagonals and 2*3*2 interior grid lines.
  EXPECT_EQ(shared_edges, 9 + 12);
}

TEST(ContactFind, SphereToolNearTheFace) {
  const BoxFixture box;
  const double radius = 0.05;
  const ContactQuery touching =
      find_contact(box.mesh, box.surface, box.normals, box.top, Vector3d(0.45, 0.55, 1.02), radius);
  EXPECT_NEAR(touching.signed_distance, 0.02, 1e-12);
  ASSERT_TRUE(touching.contact.has_value());
  EXPECT_NEAR(touching.contact->depth, 0.03, 1e-12);
  EXPECT_LT((touching.contact->displacement - Vector3d(0, 0, -0.03)).norm(), 1e-12);
  EXPECT_LT((touching.contact->foot - Vector3d(0.45, 0.55, 1)).norm(), 1e-12);

  const ContactQuery apart =
      find_contact(box.mesh, box.surface, box.normals, box.top, Vector3d(0.45, 0.55, 1.06), radius);
  EXPECT_FALSE(apart.contact.has_value());
}

TEST(ContactFind, SphereAtAConvexEdgeGoesToTheFaceItIsDeepestBelow) {
  // Touchable: the faces z = 1 and x = 1. The centre (1.02, 0.5, 1.01) is outside, 0.0224
  // from the edge (x = z = 1) and within the radius; both faces' triangles reach the edge
  // point at the same distance. Its height above the plane z = 1 (0.01) is below that
  // above x = 1 (0.02), so by the documented tie rule a top triangle is chosen, and
  // d = (p - r n) - F = (1.02, 0.5, 1.01 - 0.05) - (1, 0.5, 1).
  const BoxFixture box;
  std::vector<int> touchable = box.top;
  for (int t = 0; t < box.surface.triangle_count(); ++t)
    if (box.normals.face[t].x() > 1 - 1e-12) touchable.push_back(t);
  ASSERT_EQ(touchable.size(), 36u);
  const Vector3d p(1.02, 0.5, 1.01);
  const double radius = 0.05;
  for (bool reverse : {false, true}) {
    std::vector<int> order = touchable;
    if (reverse) std::reverse(order.begin(), order.end());
    const ContactQuery query = find_contact(box.mesh, box.surface, box.normals, order, p, radius);
    EXPECT_NEAR(query.signed_distance, std::hypot(0.02, 0.01), 1e-12);
    ASSERT_TRUE(query.contact.has_value());
    EXPECT_NE(std::find(box.top.begin(), box.top.end(), query.contact->triangle), box.top.end())
        << "reverse " << reverse;
    EXPECT_LT((query.contact->foot - Vector3d(1, 0.5, 1)).norm(), 1e-12);
    EXPECT_LT((query.contact->displacement - Vector3d(0.02, 0, -0.04)).norm(), 1e-12);
    EXPECT_NEAR(query.contact->depth, 0.04, 1e-12);  // -d . n with n = +z
  }
}

}  // namespace
}  // namespace cohaptic
