// LinkImpairment: the per-packet decisions of cvslam_link_shaper (netem in user space).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "link_shaper/link_impairment.h"

namespace cvslam::link {
namespace {

struct Outcome {
  int dropped = 0;
  std::vector<double> delays_ms;  ///< of the packets let through, in arrival order
  std::vector<double> releases_s;
};

Outcome send(const LinkImpairmentOptions& o, int packets, double spacing_s, std::size_t bytes) {
  LinkImpairment link(o);
  Outcome out;
  for (int k = 0; k < packets; ++k) {
    const double t = k * spacing_s;
    const LinkDecision d = link.decide(t, bytes);
    if (d.drop) {
      ++out.dropped;
      continue;
    }
    out.delays_ms.push_back(1000.0 * (d.release_s - t));
    out.releases_s.push_back(d.release_s);
  }
  return out;
}

double mean(const std::vector<double>& x) {
  double s = 0.0;
  for (double v : x) s += v;
  return s / static_cast<double>(x.size());
}

TEST(LinkImpairment, LossRateMatchesItsProbability) {
  LinkImpairmentOptions o;
  o.loss_percent = 20.0;
  o.seed = 3;
  const int n = 20000;
  const Outcome out = send(o, n, 0.001, 100);
  // Binomial(20000, 0.2): σ = 57 packets; 4σ.
  EXPECT_NEAR(out.dropped, 0.2 * n, 4.0 * std::sqrt(n * 0.2 * 0.8));
}

TEST(LinkImpairment, DelayIsUniformAroundItsMean) {
  LinkImpairmentOptions o;
  o.delay_ms = 50.0;
  o.jitter_ms = 10.0;
  const Outcome out = send(o, 10000, 0.001, 100);
  ASSERT_EQ(out.dropped, 0);
  const auto [lo, hi] = std::minmax_element(out.delays_ms.begin(), out.delays_ms.end());
  EXPECT_GE(*lo, 40.0);
  EXPECT_LE(*hi, 60.0);
  EXPECT_NEAR(mean(out.delays_ms), 50.0, 0.2);  // σ of the mean: 5.77/√10⁴ = 0.06 ms
  double var = 0.0;
  for (double d : out.delays_ms) var += (d - 50.0) * (d - 50.0);
  EXPECT_NEAR(std::sqrt(var / out.delays_ms.size()), 10.0 / std::sqrt(3.0), 0.15);
}

TEST(LinkImpairment, JitterReordersUnlessTheLinkIsFifo) {
  LinkImpairmentOptions o;
  o.delay_ms = 50.0;
  o.jitter_ms = 10.0;
  auto overtaken = [](const std::vector<double>& r) {
    int n = 0;
    for (std::size_t k = 1; k < r.size(); ++k) n += r[k] < r[k - 1] ? 1 : 0;
    return n;
  };
  EXPECT_GT(overtaken(send(o, 1000, 0.002, 100).releases_s), 100);
  o.reorder = false;
  const Outcome fifo = send(o, 1000, 0.002, 100);
  EXPECT_EQ(overtaken(fifo.releases_s), 0);
  EXPECT_GE(*std::min_element(fifo.delays_ms.begin(), fifo.delays_ms.end()), 40.0);
}

TEST(LinkImpairment, RateLimitQueuesABurst) {
  LinkImpairmentOptions o;
  o.rate_kbit = 800.0;  // 100 bytes per ms
  // 50 packets of 1000 bytes at once: each takes 10 ms on the link.
  const Outcome out = send(o, 50, 0.0, 1000);
  for (std::size_t k = 0; k < out.releases_s.size(); ++k) {
    EXPECT_NEAR(out.releases_s[k], 0.010 * static_cast<double>(k + 1), 1e-12);
  }
}

TEST(LinkImpairment, OneSeedOnePatternAndJitterIndependentOfLoss) {
  LinkImpairmentOptions o;
  o.loss_percent = 30.0;
  o.delay_ms = 20.0;
  o.jitter_ms = 5.0;
  o.seed = 9;
  const Outcome a = send(o, 500, 0.01, 100), b = send(o, 500, 0.01, 100);
  EXPECT_EQ(a.releases_s, b.releases_s);
  o.seed = 10;
  EXPECT_NE(send(o, 500, 0.01, 100).releases_s, a.releases_s);
}

TEST(LinkImpairment, ValidationNamesTheBadValue) {
  LinkImpairmentOptions o;
  EXPECT_EQ(o.validate(), "");
  o.loss_percent = 101.0;
  EXPECT_NE(o.validate().find("loss"), std::string::npos);
  o = {};
  o.jitter_ms = -1.0;
  EXPECT_NE(o.validate().find("jitter"), std::string::npos);
  o = {};
  o.delay_ms = std::nan("");
  EXPECT_NE(o.validate().find("delay"), std::string::npos);
  o = {};
  o.rate_kbit = -5.0;
  EXPECT_NE(o.validate().find("rate"), std::string::npos);
}

}  // namespace
}  // namespace cvslam::link
