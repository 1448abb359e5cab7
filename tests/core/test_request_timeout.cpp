// RequestTimeout: the per-peer timer of DC requests (RFC 6298 in dataset time).
#include "cvslam/coop/request_timeout.h"

#include <gtest/gtest.h>

#include <limits>

namespace cvslam::coop {
namespace {

TEST(RequestTimeout, StartsAtTheFloorAndFollowsTheRoundTrip) {
  RequestTimeout t({0.3, 2.0});
  EXPECT_DOUBLE_EQ(t.seconds(), 0.3);
  EXPECT_LT(t.smoothedRoundTrip(), 0.0);
  // First sample R: SRTT = R, RTTVAR = R/2, RTO = R + 4·R/2 = 3R (RFC 6298 §2.2).
  t.onAnswer(0.2);
  EXPECT_DOUBLE_EQ(t.smoothedRoundTrip(), 0.2);
  EXPECT_NEAR(t.seconds(), 0.6, 1e-12);
  // A steady round trip: RTTVAR decays by 3/4 per answer, RTO → SRTT, held at the floor.
  for (int k = 0; k < 50; ++k) t.onAnswer(0.2);
  EXPECT_NEAR(t.smoothedRoundTrip(), 0.2, 1e-9);
  EXPECT_DOUBLE_EQ(t.seconds(), 0.3);
}

TEST(RequestTimeout, SlowAnswersRaiseItUpToTheCeiling) {
  RequestTimeout t({0.3, 2.0});
  for (int k = 0; k < 50; ++k) t.onAnswer(0.8);
  EXPECT_NEAR(t.seconds(), 0.8, 1e-4);  // the round trip, no spurious timeouts
  for (int k = 0; k < 50; ++k) t.onAnswer(5.0);
  EXPECT_DOUBLE_EQ(t.seconds(), 2.0);
}

TEST(RequestTimeout, TimeoutsBackOffByDoublingUpToTheCeiling) {
  RequestTimeout t({0.5, 2.0});
  t.onTimeout();
  EXPECT_DOUBLE_EQ(t.seconds(), 1.0);
  t.onTimeout();
  EXPECT_DOUBLE_EQ(t.seconds(), 2.0);
  t.onTimeout();
  EXPECT_DOUBLE_EQ(t.seconds(), 2.0);
  // An answer brings it back to the measured round trip.
  t.onAnswer(0.2);
  EXPECT_NEAR(t.seconds(), 0.6, 1e-12);
}

TEST(RequestTimeout, IgnoresImpossibleSamples) {
  RequestTimeout t({0.5, 2.0});
  t.onAnswer(-1.0);
  t.onAnswer(std::numeric_limits<double>::quiet_NaN());
  EXPECT_LT(t.smoothedRoundTrip(), 0.0);
  EXPECT_DOUBLE_EQ(t.seconds(), 0.5);
}

}  // namespace
}  // namespace cvslam::coop
