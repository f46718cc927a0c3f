// The link shim against what each option must do: exact delay, loss rates within binomial
// bounds, bursts, an outage window, reordering under jitter (and none when told to keep order),
// and the same run for the same seed.
#include "hapsim/net/link_shim.h"

#include "support/allocation_counter.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

constexpr std::size_t kCapacity = 256;
using Shim = LinkShim<int, kCapacity>;

// Sends one sample per millisecond for `count` ms and records each arrival (value, time).
struct Arrival {
  int value;
  double at_s;
};
std::vector<Arrival> run(Shim& shim, int count) {
  std::vector<Arrival> arrivals;
  for (int k = 0; k < count + 1000; ++k) {
    const double now_s = 1e-3 * k;
    if (k < count) {
      shim.send(k, now_s);
    }
    shim.deliver(now_s, [&](const int& v) { arrivals.push_back({v, now_s}); });
  }
  return arrivals;
}

TEST(LinkShim, DelaysEverySampleExactly) {
  Shim shim({.delay_s = 0.020});
  const std::vector<Arrival> a = run(shim, 100);
  ASSERT_EQ(a.size(), 100u);
  for (const Arrival& x : a) {
    EXPECT_NEAR(x.at_s - 1e-3 * x.value, 0.020, 1e-9);
  }
  EXPECT_EQ(shim.counts().reordered, 0u);
}

TEST(LinkShim, IndependentLossIsWithinBinomialBounds) {
  constexpr int kCount = 20000;
  Shim shim({.loss = 0.3, .seed = 7});
  const std::vector<Arrival> a = run(shim, kCount);
  const double lost = static_cast<double>(kCount - static_cast<int>(a.size()));
  const double sigma = std::sqrt(kCount * 0.3 * 0.7);
  EXPECT_NEAR(lost, kCount * 0.3, 5.0 * sigma);
  EXPECT_EQ(shim.counts().lost_random, static_cast<std::uint64_t>(lost));
}

TEST(LinkShim, BurstsLoseRunsOfTheExpectedMeanLength) {
  // Leaving a burst with probability 0.25 per sample: bursts last 1/0.25 = 4 samples on average.
  constexpr int kCount = 50000;
  Shim shim({.burst_enter = 0.01, .burst_exit = 0.25, .seed = 3});
  const std::vector<Arrival> a = run(shim, kCount);
  std::vector<bool> arrived(kCount, false);
  for (const Arrival& x : a) {
    arrived[static_cast<std::size_t>(x.value)] = true;
  }
  int runs = 0;
  int lost = 0;
  for (int k = 0; k < kCount; ++k) {
    if (!arrived[static_cast<std::size_t>(k)]) {
      ++lost;
      runs += (k == 0 || arrived[static_cast<std::size_t>(k - 1)]) ? 1 : 0;
    }
  }
  ASSERT_GT(runs, 100);
  EXPECT_NEAR(static_cast<double>(lost) / runs, 4.0, 0.5);
  EXPECT_EQ(shim.counts().lost_burst, static_cast<std::uint64_t>(lost));
}

TEST(LinkShim, AnOutageIsALinkDownForItsWindow) {
  Shim shim({.delay_s = 0.005, .outage_start_s = 0.100, .outage_s = 0.300});
  const std::vector<Arrival> a = run(shim, 1000);
  // Nothing arrives in [100, 400) ms: what was sent in it is lost, and so is what was sent in
  // the 5 ms before it, still on the wire when the link went down (95 to 99 ms).
  EXPECT_EQ(a.size(), 695u);
  for (const Arrival& x : a) {
    EXPECT_TRUE(x.at_s < 0.100 - 1e-9 || x.at_s >= 0.400 - 1e-9) << x.at_s;
    EXPECT_TRUE(x.value < 95 || x.value >= 400) << x.value;
  }
  EXPECT_EQ(shim.counts().lost_outage, 305u);
}

TEST(LinkShim, JitterReordersUnlessToldToKeepOrder) {
  Shim loose({.delay_s = 0.010, .jitter_s = 0.005, .seed = 11});
  const std::vector<Arrival> a = run(loose, 2000);
  EXPECT_EQ(a.size(), 2000u);
  EXPECT_GT(loose.counts().reordered, 0u);
  for (const Arrival& x : a) {
    const double delay_s = x.at_s - 1e-3 * x.value;
    EXPECT_GE(delay_s, 0.010 - 1e-9);
    EXPECT_LE(delay_s, 0.016 + 1e-9);  // 5 ms of jitter, due on the next 1 ms tick
  }
  Shim ordered({.delay_s = 0.010, .jitter_s = 0.005, .keep_order = true, .seed = 11});
  const std::vector<Arrival> b = run(ordered, 2000);
  EXPECT_EQ(ordered.counts().reordered, 0u);
  for (std::size_t i = 1; i < b.size(); ++i) {
    EXPECT_GT(b[i].value, b[i - 1].value);
  }
}

TEST(LinkShim, SameSeedSameRunAndNoAllocation) {
  const LinkShimOptions o{.delay_s = 0.02,
                          .jitter_s = 0.01,
                          .loss = 0.1,
                          .burst_enter = 0.01,
                          .burst_exit = 0.3,
                          .seed = 99};
  Shim first(o);
  Shim second(o);
  const std::vector<Arrival> a = run(first, 3000);
  const std::vector<Arrival> b = run(second, 3000);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].value, b[i].value);
  }
  Shim third(o);
  long before = hapsim::test::allocation_count();
  int delivered = 0;
  for (int k = 0; k < 3000; ++k) {  // haptic path
    third.send(k, 1e-3 * k);
    delivered += static_cast<int>(third.deliver(1e-3 * k, [](const int&) {}));
  }
  EXPECT_EQ(hapsim::test::allocation_count() - before, 0);
  EXPECT_GT(delivered, 0);
}

TEST(LinkShim, AFullLinkDropsAndCounts) {
  LinkShim<int, 4> tiny({.delay_s = 1.0});
  for (int k = 0; k < 10; ++k) {
    tiny.send(k, 0.0);
  }
  EXPECT_EQ(tiny.in_flight(), 4u);
  EXPECT_EQ(tiny.counts().lost_full, 6u);
}

}  // namespace
}  // namespace hapsim::net
