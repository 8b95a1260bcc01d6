// Clock sync, remote-tool playout, injected link delays, and the lock-free hand-overs
// between the client's threads, against hand-computed answers.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <thread>

#include "common/delay/link_delay.h"
#include "common/sync/clock_offset.h"
#include "common/sync/remote_tool_buffer.h"
#include "common/util/error.h"
#include "common/util/histogram.h"
#include "common/util/spsc_ring.h"
#include "common/util/triple_buffer.h"

namespace cohaptic {
namespace {

TEST(ClockOffset, SymmetricDelaysGiveTheExactOffsetAndTheSmallestRoundTripWins) {
  ClockOffsetEstimator clock(8);
  EXPECT_FALSE(clock.valid());
  const std::int64_t offset = 123'456'789;  // server = client + offset
  // A ping with 3 ms each way and 1 ms at the server; then noisier ones.
  const auto ping = [&](std::int64_t t0, std::int64_t up, std::int64_t server, std::int64_t down) {
    const std::int64_t t1 = t0 + up + offset, t2 = t1 + server, t3 = t2 - offset + down;
    clock.add(t0, t1, t2, t3);
  };
  ping(0, 3'000'000, 1'000'000, 3'000'000);
  EXPECT_EQ(clock.offset_ns(), offset);
  EXPECT_EQ(clock.round_trip_ns(), 6'000'000);
  ping(10'000'000, 9'000'000, 0, 1'000'000);  // asymmetric: 4 ms error, but a 10 ms round trip
  EXPECT_EQ(clock.offset_ns(), offset) << "the smaller round trip still wins";
  ping(20'000'000, 500'000, 0, 500'000);
  EXPECT_EQ(clock.round_trip_ns(), 1'000'000);
  EXPECT_EQ(clock.to_client(clock.to_server(42)), 42);
  // The window forgets: after 8 worse samples the best one has left it.
  for (int i = 0; i < 8; ++i) ping(30'000'000 + i, 2'000'000, 0, 2'000'000);
  EXPECT_EQ(clock.round_trip_ns(), 4'000'000);
}

TEST(RemoteToolBuffer, FixedPlayoutInterpolatesAtTheDelayAndHoldsTheNewest) {
  RemoteToolBuffer buffer(PlayoutPolicy::fixed, 5'000'000);
  EXPECT_FALSE(buffer.at(0).valid);
  // Samples every ms along x = t (in ms), arriving 2 ms later.
  for (int ms = 0; ms <= 20; ++ms)
    buffer.add(ms * 1'000'000LL, ms * 1'000'000LL + 2'000'000, Eigen::Vector3d(ms, 0, 0), true);
  const PlayoutQuery at = buffer.at(15'500'000);  // plays 10.5 ms
  ASSERT_TRUE(at.valid);
  EXPECT_NEAR(at.position.x(), 10.5, 1e-12);
  EXPECT_EQ(at.age_ns, 5'000'000);
  const PlayoutQuery late = buffer.at(40'000'000);  // beyond the newest: hold it
  EXPECT_NEAR(late.position.x(), 20, 1e-12);
  EXPECT_EQ(late.age_ns, 20'000'000);
  // Out of order samples are dropped and counted.
  buffer.add(19'500'000, 0, Eigen::Vector3d(99, 0, 0), true);
  EXPECT_EQ(buffer.dropped_out_of_order(), 1u);
}

TEST(RemoteToolBuffer, NewestIgnoresTheDelayAndAdaptiveFollowsTheSampleAge) {
  RemoteToolBuffer newest(PlayoutPolicy::newest, 5'000'000);
  RemoteToolBuffer adaptive(PlayoutPolicy::adaptive, 1'000'000);
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> jitter_us(0, 8000);
  for (int ms = 0; ms < 1000; ++ms) {
    const std::int64_t t = ms * 1'000'000LL;
    const std::int64_t arrival =
        t + 10'000'000 + jitter_us(rng) * 1000LL;  // 10-18 ms old on arrival
    newest.add(t, arrival, Eigen::Vector3d(ms, 0, 0), true);
    adaptive.add(t, arrival, Eigen::Vector3d(ms, 0, 0), true);
  }
  EXPECT_NEAR(newest.at(1e9).position.x(), 999, 1e-12);
  // 95th percentile of U(10, 18) ms is 17.6 ms; plus the 1 ms margin, in 0.25 ms bins.
  EXPECT_NEAR(static_cast<double>(adaptive.playout_delay_ns()) * 1e-6, 18.6, 0.3);
}

TEST(RemoteToolBuffer, AnInvalidSampleMakesThePlayoutInvalidUntilValidOnesReturn) {
  RemoteToolBuffer buffer(PlayoutPolicy::newest, 0);
  buffer.add(1, 1, Eigen::Vector3d::Ones(), true);
  buffer.add(2, 2, Eigen::Vector3d::Zero(), false);
  EXPECT_FALSE(buffer.at(3).valid);
  buffer.add(3, 3, Eigen::Vector3d::Constant(NAN), true);  // non-finite counts as invalid
  EXPECT_FALSE(buffer.at(4).valid);
  buffer.add(4, 4, Eigen::Vector3d::Ones(), true);
  EXPECT_TRUE(buffer.at(5).valid);
}

TEST(LinkDelay, ConstantJitterLossAndReorderingFollowTheSettings) {
  LinkDelaySettings settings;
  settings.delay_ms = 30;
  settings.jitter_ms = 4;
  settings.loss = 0.1;
  settings.reorder = 0.05;
  settings.seed = 9;
  LinkDelay link(settings, false);
  int lost = 0, late = 0;
  const int messages = 20000;
  double min_ms = 1e9, max_ms = 0;
  for (int i = 0; i < messages; ++i) {
    const auto delay = link.delay_ns(i * 1'000'000LL);
    if (!delay) {
      ++lost;
      continue;
    }
    const double ms = static_cast<double>(*delay) * 1e-6;
    min_ms = std::min(min_ms, ms);
    max_ms = std::max(max_ms, ms);
    late += ms > 34;
  }
  EXPECT_NEAR(lost / double(messages), 0.1, 0.01);
  EXPECT_GE(min_ms, 30);
  EXPECT_LE(max_ms, 30 + 4 + 2 * 4 + 1);
  EXPECT_NEAR(late / double(messages - lost), 0.05, 0.01);
  // Same seed, same fates.
  LinkDelay again(settings, false);
  LinkDelay first(settings, false);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(again.delay_ns(i), first.delay_ns(i));
  // An ordered link loses nothing and never reorders: each delivery strictly after the last.
  LinkDelay ordered(settings, true);
  std::int64_t last_delivery = 0;
  for (int i = 0; i < 1000; ++i) {
    const auto delay = ordered.delay_ns(i * 100'000LL);
    ASSERT_TRUE(delay.has_value());
    EXPECT_GT(i * 100'000LL + *delay, last_delivery);
    last_delivery = i * 100'000LL + *delay;
  }
  settings.loss = 1.5;
  EXPECT_THROW(validate(settings), Error);
}

TEST(ThreadHandOver, TheSpscRingDeliversEverythingInOrderAcrossThreads) {
  SpscRing<std::int64_t, 1024> ring;
  constexpr std::int64_t kCount = 200000;
  std::thread producer([&] {
    for (std::int64_t i = 0; i < kCount;)
      if (ring.push(i)) ++i;
  });
  std::int64_t expected = 0;
  while (expected < kCount)
    if (const auto value = ring.pop()) {
      ASSERT_EQ(*value, expected);
      ++expected;
    }
  producer.join();
  EXPECT_FALSE(ring.pop().has_value());
}

TEST(ThreadHandOver, TheTripleBufferNeverShowsATornValueAndEndsOnTheNewest) {
  struct Pair {
    std::int64_t a = 0, b = 0;  // always written equal
  };
  TripleBuffer<Pair> buffer;
  constexpr std::int64_t kCount = 200000;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (std::int64_t i = 1; i <= kCount; ++i) {
      buffer.back() = {i, i};
      buffer.publish();
    }
    done = true;
  });
  std::int64_t last = 0;
  while (!done || buffer.update()) {
    buffer.update();
    const Pair& p = buffer.front();
    ASSERT_EQ(p.a, p.b);
    ASSERT_GE(p.a, last) << "values only move forward";
    last = p.a;
  }
  writer.join();
  buffer.update();
  EXPECT_EQ(buffer.front().a, kCount);
}

TEST(Histogram, QuantilesOfKnownDistributions) {
  Histogram h(1000, 100);                                            // 1 us bins up to 100 us
  for (int v = 1; v <= 100000; ++v) h.record(v % 100 * 1000 + 500);  // uniform over the bins
  EXPECT_EQ(h.quantile(0.5), 50'000);
  EXPECT_EQ(h.quantile(0.99), 99'000);
  EXPECT_EQ(h.max(), 99'500);
  h.record(5'000'000);  // beyond the range: last bin, exact max
  EXPECT_EQ(h.max(), 5'000'000);
}

}  // namespace
}  // namespace cohaptic
