// The nearest-triangle rule (common/contact/nearest_triangle_rule.h) on hand-made offers
// whose answer follows from the rule's statement. (That the server and the client choose
// the same triangle on real surfaces is tested in test_contact and test_extremes.)
#include <gtest/gtest.h>

#include "common/contact/nearest_triangle_rule.h"

namespace cohaptic {
namespace {

TEST(NearestTriangleRule, TheFirstOfferIsTakenAndANearerOneReplacesIt) {
  NearestTriangleRule rule;
  EXPECT_EQ(rule.surface_index(), -1);
  EXPECT_TRUE(rule.offer(4e-6, 1e-3, 7));
  EXPECT_TRUE(rule.offer(1e-6, 2e-3, 9));  // nearer, even if higher above its plane
  EXPECT_EQ(rule.surface_index(), 9);
  EXPECT_DOUBLE_EQ(rule.height(), 2e-3);
  EXPECT_FALSE(rule.offer(2e-6, -5e-3, 3));  // farther, even if deeper and of lower index
  EXPECT_EQ(rule.surface_index(), 9);
}

TEST(NearestTriangleRule, AtTheSameDistanceTheDeeperPlaneWinsThenTheLowerIndex) {
  NearestTriangleRule rule;
  rule.offer(1e-6, 1e-3, 5);
  // Equal within rounding (1 part in 1e14): a tie, decided by the height.
  EXPECT_TRUE(rule.offer(1e-6 * (1 + 1e-14), -1e-3, 8));
  EXPECT_EQ(rule.surface_index(), 8);
  EXPECT_FALSE(rule.offer(1e-6, 0.0, 2));  // tied distance, higher: keeps 8
  // Tied distance and height: the lower index.
  EXPECT_TRUE(rule.offer(1e-6, -1e-3, 4));
  EXPECT_EQ(rule.surface_index(), 4);
  EXPECT_FALSE(rule.offer(1e-6, -1e-3, 6));
  EXPECT_EQ(rule.surface_index(), 4);
}

TEST(NearestTriangleRule, TheTieToleranceIsRelativeWithAnAbsoluteFloor) {
  // 1e-10 relative is beyond the tolerance: strictly nearer.
  EXPECT_TRUE(strictly_nearer(1e-6 * (1 - 1e-10), 1e-6));
  EXPECT_FALSE(strictly_nearer(1e-6 * (1 - 1e-13), 1e-6));
  // At zero distance only the absolute floor (1e-24 m^2) separates.
  EXPECT_FALSE(strictly_nearer(0.0, 0.5e-24));
  EXPECT_TRUE(strictly_nearer(0.0, 2e-24));
}

}  // namespace
}  // namespace cohaptic
