// The separation body's haptic-rate contact:
// a pushing tool slides by Coulomb friction and stops at a crack edge, lets go when it
// would pull; the evaluation allocates nothing, never outputs NaN or more than the force
// limit, and the same inputs give the same bits on a copy of the patch (client = server).
#include <gtest/gtest.h>

#include <malloc.h>

#include <Eigen/LU>

#include <atomic>

#include "common/separation/laser_groove.h"
#include "common/separation/pull_loop.h"
#include "common/separation/separation_setup.h"
#include "support/default_two_layers.h"
#include "support/sanitizer_owns_malloc.h"

namespace {
std::atomic<bool> counting_frees{false};
std::atomic<long> frees{0};
}  // namespace

#ifndef COHAPTIC_SANITIZER_OWNS_MALLOC
extern "C" void __libc_free(void* pointer);  // glibc's own, behind the one below

// Counts frees while the flag is set: a haptic path that allocated and released memory
// would show here, one that kept it would show in mallinfo2's in-use bytes.
extern "C" void free(void* pointer) {
  if (pointer && counting_frees.load(std::memory_order_relaxed))
    frees.fetch_add(1, std::memory_order_relaxed);
  __libc_free(pointer);
}
#endif

namespace cohaptic {
namespace {

using testing::default_two_layers;

// An opened strip along the free rim: every triangle with its centroid at x < 10 mm.
SeparationState opened_strip(const SeparationPatch& patch) {
  SeparationState state = make_separation_state(patch);
  std::vector<int> strip;
  for (int t = 0; t < patch.triangle_count(); ++t)
    if (patch.centroids[t].x() < 0.010) strip.push_back(t);
  separate_triangles(patch, state, strip);
  return state;
}

ContactPoint point_at(const SeparationPatch& patch, const Eigen::Vector3d& p) {
  for (int t = 0; t < patch.triangle_count(); ++t) {
    const Triangle& tri = patch.triangles[t];
    Eigen::Matrix2d e;
    e << patch.positions.col(tri[1]).head<2>() - patch.positions.col(tri[0]).head<2>(),
        patch.positions.col(tri[2]).head<2>() - patch.positions.col(tri[0]).head<2>();
    const Eigen::Vector2d uv = e.inverse() * (p.head<2>() - patch.positions.col(tri[0]).head<2>());
    if (uv.minCoeff() >= 0 && uv.sum() <= 1) {
      ContactPoint point;
      point.triangle = t;
      point.weights = Eigen::Vector3d(1 - uv.sum(), uv.x(), uv.y());
      return point;
    }
  }
  ADD_FAILURE() << "no triangle under " << p.transpose();
  return {};
}

// A tool under the opened flap presses it up and drags it towards the connected tissue:
// c slides with |F_t| = mu (F . n), stops where the opened strip ends (x = 10 mm), and the
// force then builds up until the flap tears there.
TEST(SeparationContact, SlidingStopsAtACrackEdge) {
  const SeparationPatch& patch = default_two_layers().patch;
  SeparationState state = opened_strip(patch);
  const Eigen::Vector3d start(0.005, 0.0203, 0);
  SeparationContact contact =
      begin_contact(patch, ContactMode::push, point_at(patch, start), start);
  ASSERT_EQ(contact.mode, ContactMode::push);
  const Eigen::Vector3d press(0, 0, 0.001);
  for (int i = 1; i <= 100; ++i) step_contact(patch, state, contact, start + press * (i / 100.0));
  bool slid = false, stopped = false, tore = false;
  double stop_x = 0, force_at_stop = 0;
  for (int i = 1; i <= 1200 && !tore; ++i) {
    const SeparationSample s =
        step_contact(patch, state, contact, start + press + Eigen::Vector3d(1e-5 * i, 0, 0));
    const Eigen::Vector3d n = patch.normals[contact.point.triangle];
    const double normal = s.body_force.dot(n);
    const double tangential = (s.body_force - normal * n).norm();
    ASSERT_TRUE(s.flags & kSeparationInContact) << "tick " << i;
    if (!stopped && (s.flags & kSeparationStoppedAtCrackEdge)) {
      stopped = true;
      stop_x = contact.position.x();
      force_at_stop = s.body_force.x();
      continue;
    }
    if (!stopped && (s.flags & kSeparationSliding)) {
      slid = true;
      EXPECT_NEAR(tangential, patch.friction * normal, 1e-9 * normal) << "tick " << i;
    }
    tore = s.separated > 0;
    if (stopped && !tore) {
      EXPECT_NEAR(contact.position.x(), stop_x, 1e-12)
          << "c moved on from the crack edge before tearing, tick " << i;
      EXPECT_GE(s.body_force.x(), force_at_stop - 1e-12) << "tick " << i;
      force_at_stop = s.body_force.x();
    }
  }
  EXPECT_TRUE(slid);
  ASSERT_TRUE(stopped);
  EXPECT_NEAR(stop_x, 0.010, 1e-12);
  EXPECT_TRUE(tore) << "the force never reached J_c l_t at the crack edge";
}

TEST(SeparationContact, PushingToolLetsGoWhenItWouldPull) {
  const SeparationPatch& patch = default_two_layers().patch;
  SeparationState state = opened_strip(patch);
  const Eigen::Vector3d start(0.005, 0.0203, 0);
  SeparationContact contact =
      begin_contact(patch, ContactMode::push, point_at(patch, start), start);
  EXPECT_GT(step_contact(patch, state, contact, start + Eigen::Vector3d(0, 0, 2e-4)).body_force.z(),
            0);
  const SeparationSample away =
      step_contact(patch, state, contact, start - Eigen::Vector3d(0, 0, 1e-4));
  EXPECT_TRUE(away.flags & kSeparationReleased);
  EXPECT_EQ(contact.mode, ContactMode::none);
  EXPECT_EQ(away.force, Eigen::Vector3d::Zero());
  EXPECT_EQ(step_contact(patch, state, contact, start).force, Eigen::Vector3d::Zero());
  // Invalid starts make no contact.
  ContactPoint bad = point_at(patch, start);
  bad.weights = Eigen::Vector3d(0.5, 0.6, 0);
  EXPECT_EQ(begin_contact(patch, ContactMode::grasp, bad, start).mode, ContactMode::none);
  bad = point_at(patch, start);
  bad.tool_nodes = {0, 0, 3};
  EXPECT_EQ(begin_contact(patch, ContactMode::grasp, bad, start).mode, ContactMode::none);
}

// Thousands of ticks of pulling, tearing, sliding and lasering: no allocation, no free,
// never a NaN, never more than the force limit.
TEST(SeparationContact, EvaluationAllocatesNothingAndStaysBounded) {
  const SeparationPatch& patch = default_two_layers().patch;
  SeparationState state = make_separation_state(patch);
  const int node = nearest_patch_node(patch, Eigen::Vector3d(0, 0.02, 0));
  const Eigen::Vector3d start = patch.positions.col(node);
  SeparationContact grasp =
      begin_contact(patch, ContactMode::grasp, contact_at_node(patch, node), start);
  SeparationContact push =
      begin_contact(patch, ContactMode::push, contact_at_node(patch, node), start);
  const int middle = nearest_patch_node(patch, Eigen::Vector3d(0.02, 0.02, 0));
  const Eigen::Vector3d centre = patch.positions.col(middle);
  SeparationContact stuck =
      begin_contact(patch, ContactMode::grasp, contact_at_node(patch, middle), centre);
  LaserFibre fibre;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int fractures = 0, clamped = 0, non_finite = 0;
  // Warm-up tick outside the window (lazy one-time initialisation anywhere below).
  step_contact(patch, state, grasp, start);
  [[maybe_unused]] const std::size_t in_use = mallinfo2().uordblks;
  frees = 0;
  counting_frees = true;
  for (int i = 1; i <= 3000; ++i) {
    const double t = i * 1e-3;
    const Eigen::Vector3d pull =
        start + Eigen::Vector3d(0.004 * std::sin(3 * t), 0.002 * std::sin(5 * t), 0.012 * t);
    const SeparationSample s = step_contact(patch, state, grasp, pull);
    fractures += (s.flags & kSeparationFracture) != 0;
    clamped += (s.flags & kSeparationClamped) != 0;
    sum += s.force;
    if (!s.force.allFinite() || s.force.norm() > patch.force_limit * (1 + 1e-12)) ++non_finite;
    sum += step_contact(patch, state, push, start + Eigen::Vector3d(1e-5 * i, 0, 5e-4)).force;
    const SeparationSample held =
        step_contact(patch, state, stuck, centre + Eigen::Vector3d(0, 0, 2e-5 * i));
    clamped += (held.flags & kSeparationClamped) != 0;
    if (!held.force.allFinite() || held.force.norm() > patch.force_limit * (1 + 1e-12))
      ++non_finite;
    step_laser(patch, state, fibre, Eigen::Vector3d(0.02, 0.005 + 1e-5 * i, 0), true, 1e-3);
  }
  const SeparationSample nan =
      step_contact(patch, state, grasp, Eigen::Vector3d(std::nan(""), 0, 0));
  counting_frees = false;
#ifndef COHAPTIC_SANITIZER_OWNS_MALLOC  // the plain build counts (support/sanitizer_owns_malloc.h)
  EXPECT_EQ(frees.load(), 0) << "the haptic path freed memory it allocated";
  EXPECT_EQ(mallinfo2().uordblks, in_use) << "the haptic path kept memory it allocated";
#endif
  EXPECT_GT(fractures, 0);
  EXPECT_GT(clamped, 0) << "the pull never reached the force limit";
  EXPECT_EQ(non_finite, 0);
  EXPECT_TRUE(sum.allFinite());
  EXPECT_EQ(nan.force, Eigen::Vector3d::Zero());
  EXPECT_TRUE(nan.flags & kSeparationNonFinite);

#ifndef COHAPTIC_SANITIZER_OWNS_MALLOC
  // The counter does see a free.
  counting_frees = true;
  {
    volatile auto* probe = new std::vector<int>(10);
    delete probe;
  }
  counting_frees = false;
  EXPECT_GT(frees.load(), 0) << "free() is not counted in this program";
#endif
}

// The client and the server run the same function on their own copies: given the same
// patch (here one rebuilt from its parts, as a receiver would) and the same tool samples,
// every force and every separated share agree to the bit.
TEST(SeparationContact, TwoCopiesAgreeBitForBit) {
  const SeparationSetup& setup = default_two_layers();
  const SeparationPatch server = setup.patch;
  const SeparationPatch client =
      make_separation_patch(setup.interface, setup.fields, SeparationSettings{});
  SeparationState server_state = make_separation_state(server),
                  client_state = make_separation_state(client);
  const int node = nearest_patch_node(server, Eigen::Vector3d(0, 0.016, 0));
  const Eigen::Vector3d start = server.positions.col(node);
  SeparationContact server_contact =
      begin_contact(server, ContactMode::grasp, contact_at_node(server, node), start);
  SeparationContact client_contact =
      begin_contact(client, ContactMode::grasp, contact_at_node(client, node), start);
  int fractures = 0;
  for (int i = 1; i <= 1500; ++i) {
    const double t = i * 1e-3;
    const Eigen::Vector3d tool =
        start + Eigen::Vector3d(0.003 * t, 0.001 * std::sin(7 * t), 0.006 * t);
    const SeparationSample a = step_contact(server, server_state, server_contact, tool);
    const SeparationSample b = step_contact(client, client_state, client_contact, tool);
    ASSERT_EQ(a.force, b.force) << "tick " << i;
    ASSERT_EQ(a.flags, b.flags) << "tick " << i;
    fractures += (a.flags & kSeparationFracture) != 0;
  }
  EXPECT_GT(fractures, 0);
  EXPECT_EQ(server_state.separated, client_state.separated);
  EXPECT_EQ(server_state.separated_area, client_state.separated_area);
  EXPECT_EQ(server_contact.position, client_contact.position);
}

}  // namespace
}  // namespace cohaptic
