// Laparoscopic instruments (common/laparoscopy/): the shaft frame through the trocar;
// forceps closing on a slab against the analytic contact angle, holding the grasp until
// release, with the home-spring force back to zero afterwards.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "common/contact/aabb_tree.h"
#include "common/laparoscopy/extract_home_spring_patch.h"
#include "common/laparoscopy/forceps_jaws.h"
#include "common/laparoscopy/home_spring_contact.h"
#include "common/laparoscopy/home_spring_force.h"
#include "common/mesh/boundary_surface.h"
#include "common/mesh/box_mesher.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

using Eigen::Vector3d;

TEST(TrocarShaft, FrameFromPivotAndTool) {
  const Vector3d pivot(0.02, 0.01, 0.15), tool(0.0, -0.01, 0.01);
  const auto frame = shaft_frame(pivot, tool, Vector3d::UnitX());
  ASSERT_TRUE(frame.has_value());
  EXPECT_LT((frame->axis - (tool - pivot).normalized()).norm(), 1e-15);
  EXPECT_NEAR(frame->opening.norm(), 1, 1e-15);
  EXPECT_NEAR(frame->opening.dot(frame->axis), 0, 1e-15);
  EXPECT_GT(frame->opening.x(), 0.9);  // the hint, made perpendicular
  const auto along = shaft_frame(Vector3d::Zero(), Vector3d(0, 0, -1), Vector3d::UnitZ());
  ASSERT_TRUE(along.has_value());
  EXPECT_NEAR(along->opening.dot(along->axis), 0, 1e-15);
  EXPECT_NEAR(along->opening.norm(), 1, 1e-15);
  EXPECT_FALSE(shaft_frame(pivot, pivot, Vector3d::UnitX()).has_value());
}

/// A slab |x - centre| <= thickness / 2, -0.03 <= z <= 0 (its top edge face at z = 0),
/// wide in y, meshed and its boundary taken as the surface.
struct Slab {
  TetMesh mesh;
  BoundarySurface surface;
};

Slab make_slab(double centre, double thickness) {
  Slab slab{make_box_mesh(Vector3d(centre - thickness / 2, -0.03, -0.03),
                          Vector3d(thickness, 0.06, 0.03), Eigen::Vector3i(2, 12, 6)),
            {}};
  slab.surface = extract_boundary_surface(slab.mesh);
  return slab;
}

constexpr double kJawLength = 0.02;
constexpr double kZHinge = 0.006;  // B above the slab's top face

TEST(Forceps, JawsStopWithinOneIncrementOfTheContactAngle) {
  const ForcepsGeometry geometry{kJawLength, 0.6, 0.004};
  for (const double offset : {0.0, 0.0012}) {
    const double thickness = 0.004;
    const Slab slab = make_slab(offset, thickness);
    const AabbTree tree(slab.mesh.nodes, slab.surface.triangles);
    // Shaft straight down onto the slab's top edge; jaws open along +-x.
    const Vector3d hinge(0, 0.001, kZHinge);
    const auto frame = shaft_frame(hinge + Vector3d(0, 0, 0.2), hinge, Vector3d::UnitX());
    ASSERT_TRUE(frame.has_value());
    ForcepsJaws jaws = open_forceps(geometry);
    for (int step = 0; step < 400 && !jaws.grasping; ++step)
      step_forceps(geometry, *frame, true, tree, jaws);
    ASSERT_TRUE(jaws.grasping) << "offset " << offset;
    // Jaw k is first stopped by the slab's top corner at x = offset +- thickness/2, z = 0:
    // tan(angle) = |x_corner| / z_hinge.
    for (int k = 0; k < 2; ++k) {
      const double side = k == 0 ? 1 : -1;
      const double corner = std::abs(offset + side * thickness / 2);
      const double contact = std::atan(corner / kZHinge);
      const double angle = jaws.angle[static_cast<std::size_t>(k)];
      EXPECT_LE(angle, contact + 1e-12) << "jaw " << k << " offset " << offset;
      EXPECT_GT(angle, contact - geometry.closing_step) << "jaw " << k << " offset " << offset;
      EXPECT_NEAR(jaws.contact[static_cast<std::size_t>(k)].z(), 0, 1e-12);
    }
    // Midway between the two contacts, each within one increment of its corner.
    EXPECT_NEAR(jaws.grasp_point.x(), offset, 2 * kZHinge * geometry.closing_step);
  }
}

TEST(Forceps, NothingBetweenTheJawsClosesThemFully) {
  const ForcepsGeometry geometry{kJawLength, 0.6, 0.05};
  const Slab slab = make_slab(0.1, 0.004);  // far to the side
  const AabbTree tree(slab.mesh.nodes, slab.surface.triangles);
  const auto frame = shaft_frame(Vector3d(0, 0, 0.2), Vector3d(0, 0, kZHinge), Vector3d::UnitX());
  ForcepsJaws jaws = open_forceps(geometry);
  for (int step = 0; step < 40; ++step) step_forceps(geometry, *frame, true, tree, jaws);
  EXPECT_FALSE(jaws.grasping);
  EXPECT_EQ(jaws.angle[0], 0.0);
  EXPECT_EQ(jaws.angle[1], 0.0);
  EXPECT_THROW(open_forceps({kJawLength, 2.0, 0.01}), Error);
  EXPECT_THROW(open_forceps({0, 0.5, 0.01}), Error);
}

TEST(Forceps, GraspHoldsUntilReleaseAndTheForceReturnsToZero) {
  const ForcepsGeometry geometry{kJawLength, 0.6, 0.004};
  const Slab slab = make_slab(0, 0.004);
  const AabbTree tree(slab.mesh.nodes, slab.surface.triangles);
  const Vector3d pivot(0, 0.001, 0.2);
  Vector3d tool(0, 0.001, kZHinge);
  ForcepsJaws jaws = open_forceps(geometry);
  for (int step = 0; step < 400 && !jaws.grasping; ++step)
    step_forceps(geometry, *shaft_frame(pivot, tool, Vector3d::UnitX()), true, tree, jaws);
  ASSERT_TRUE(jaws.grasping);
  const ForcepsJaws closed = jaws;

  // The server's side: the patch around the grasp point, the nearest vertex grasped.
  const VertexRings rings =
      vertex_rings(slab.surface.triangles, static_cast<int>(slab.mesh.nodes.cols()));
  const double k1 = 250, k2 = 80;
  HomeSpringPatch patch = extract_home_spring_patch(
      {slab.mesh.nodes, slab.surface.triangles, rings}, jaws.grasp_point, 0.012, {k1, k2}, pivot);
  patch.grasp = {nearest_touchable_vertex(patch, jaws.grasp_point), jaws.tool_at_grasp};
  const PreparedHomeSpringPatch grasped = prepare_home_spring_patch(patch);

  // Pull up and around: the jaws and the grasp point hold, the force is Eq. 8's pull-back.
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> wander(-0.004, 0.004);
  for (int step = 0; step < 300; ++step) {
    tool = jaws.tool_at_grasp + Vector3d(wander(rng), wander(rng), 0.01 * step / 300.0);
    step_forceps(geometry, *shaft_frame(pivot, tool, Vector3d::UnitX()), true, tree, jaws);
    ASSERT_TRUE(jaws.grasping);
    EXPECT_EQ(jaws.grasp_point, closed.grasp_point);
    EXPECT_EQ(jaws.angle, closed.angle);
    const HomeSpringContact contact = evaluate_home_spring(grasped, tool);
    EXPECT_EQ(contact.vertex, patch.grasp.vertex);
    const Vector3d u = tool - jaws.tool_at_grasp;
    EXPECT_LT((contact.force + home_spring_load(patch, patch.grasp.vertex, u)).norm(), 1e-12);
  }
  EXPECT_GT(tool.z(), kZHinge + 0.009);

  // Button up: jaws open, nothing held; the server's next patch has no grasp, and the
  // tool, now above the slab, touches nothing.
  step_forceps(geometry, *shaft_frame(pivot, tool, Vector3d::UnitX()), false, tree, jaws);
  EXPECT_FALSE(jaws.grasping);
  EXPECT_EQ(jaws.angle[0], geometry.open_angle);
  EXPECT_EQ(jaws.angle[1], geometry.open_angle);
  patch.grasp = {};
  const HomeSpringContact released = evaluate_home_spring(prepare_home_spring_patch(patch), tool);
  EXPECT_FALSE(released.touching);
  EXPECT_EQ(released.force, Vector3d::Zero());
}

}  // namespace
}  // namespace cohaptic
