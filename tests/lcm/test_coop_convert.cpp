// Cooperation messages ↔ lcmtypes (coop_convert.h): values survive the wire, and invalid
// messages are refused by encode/decode validation.

#include "cvslam/lcm/coop_convert.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cvslam/lcm/codec.h"
#include "lcm_test_util.h"

namespace cvslam::transport {
namespace {

using testing::throughWire;

TEST(CoopConvert, SummaryRoundTrip) {
  coop::CoopSummary s;
  s.header = {2, 17, 123456789};
  s.mode = "dc";
  s.boot_id = -987654321012345;
  s.mean = {1.5, -2.25, -10.0};
  s.std = {3.0, 4.0, 0.5};
  s.num_features = 14;
  s.vehicle_cov_trace = 0.0625;
  s.own_frame = true;
  Expected<cvslam::agent_summary_t> m = toMessage(s);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->num_channels, 0);
  const coop::CoopSummary b = fromMessage(throughWire(*m));
  EXPECT_EQ(b.header.agent_id, 2);
  EXPECT_EQ(b.header.seq, 17);
  EXPECT_EQ(b.header.t_us, 123456789);
  EXPECT_EQ(b.mode, "dc");
  EXPECT_EQ(b.boot_id, s.boot_id);
  EXPECT_EQ(b.mean, s.mean);
  EXPECT_EQ(b.std, s.std);
  EXPECT_EQ(b.num_features, 14);
  EXPECT_EQ(b.vehicle_cov_trace, 0.0625);
  EXPECT_TRUE(b.own_frame);
  s.own_frame = false;
  EXPECT_FALSE(fromMessage(throughWire(*toMessage(s))).own_frame);
}

TEST(CoopConvert, IndexAndRequestRoundTripWithLargeIndices) {
  coop::FeatureIndexList l;
  l.header = {1, 3, 1000};
  l.true_ids = true;
  l.indices = {0u, 7u, 0x7fffffffu, 0xfffffffeu};
  const coop::FeatureIndexList lb = fromMessage(throughWire(*toMessage(l)));
  EXPECT_EQ(lb.indices, l.indices);
  EXPECT_TRUE(lb.true_ids);
  EXPECT_EQ(lb.header.seq, 3);

  coop::SharedRequest r;
  r.header = {3, 0, 2000};
  r.to_agent = 1;
  r.indices = {5u, 0xffffffffu};
  const coop::SharedRequest rb = fromMessage(throughWire(*toMessage(r)), 1);
  EXPECT_EQ(rb.indices, r.indices);
  EXPECT_EQ(rb.to_agent, 1);
  EXPECT_EQ(rb.header.agent_id, 3);
}

TEST(CoopConvert, SharedLandmarksRoundTrip) {
  coop::SharedLandmarks s;
  s.header = {2, 9, 5000};
  s.to_agent = 1;
  s.vehicle_cov_trace = 1.25;
  Eigen::Matrix3d C;
  C << 0.04, 0.01, -0.002, 0.01, 0.09, 0.003, -0.002, 0.003, 0.16;
  s.landmarks.push_back({11u, {1, 2, 3}, C, {1, 2, 3, 4}});
  s.landmarks.push_back({0xfffffff0u, {-4, 5, -6}, 2.0 * C, {9, 8, 7, 6}});
  s.informed_by = {2, 5};
  s.joint_covariance = Eigen::MatrixXd::Zero(6, 6);
  s.joint_covariance.topLeftCorner<3, 3>() = C;
  s.joint_covariance.bottomRightCorner<3, 3>() = 2.0 * C;
  Eigen::Matrix3d X;  // not symmetric: the block (0,1) and its transpose (1,0)
  X << 0.01, 0.002, 0.0, -0.001, 0.02, 0.003, 0.0, 0.0, 0.03;
  s.joint_covariance.topRightCorner<3, 3>() = X;
  s.joint_covariance.bottomLeftCorner<3, 3>() = X.transpose();
  Expected<cvslam::shared_landmarks2_t> m = toMessage(s);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->descriptor_length, 4);
  EXPECT_EQ(m->num_cross, 1);
  const coop::SharedLandmarks b = fromMessage(throughWire(*m), 1);
  ASSERT_EQ(b.landmarks.size(), 2u);
  EXPECT_EQ(b.to_agent, 1);
  EXPECT_EQ(b.vehicle_cov_trace, 1.25);
  EXPECT_EQ(b.informed_by, s.informed_by);
  EXPECT_EQ(b.joint_covariance, s.joint_covariance);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(b.landmarks[i].index, s.landmarks[i].index);
    EXPECT_EQ(b.landmarks[i].p_LinN, s.landmarks[i].p_LinN);
    EXPECT_EQ(b.landmarks[i].covariance, s.landmarks[i].covariance);
    EXPECT_EQ(b.landmarks[i].descriptor, s.landmarks[i].descriptor);
  }
  // Without descriptors (feature-level simulation).
  for (auto& l : s.landmarks) l.descriptor.clear();
  const coop::SharedLandmarks nd = fromMessage(throughWire(*toMessage(s)), 1);
  EXPECT_EQ(nd.landmarks.size(), 2u);
  EXPECT_TRUE(nd.landmarks[0].descriptor.empty());
  // Marginals only: no cross blocks on the wire, no joint covariance after it.
  s.joint_covariance.resize(0, 0);
  cvslam::shared_landmarks2_t marginal = *toMessage(s);
  EXPECT_EQ(marginal.num_cross, 0);
  EXPECT_EQ(fromMessage(throughWire(marginal), 1).joint_covariance.size(), 0);
  // A cross-block count that is neither 0 nor m(m−1)/2 is refused.
  marginal.cross_covariance.assign(2, std::vector<double>(9, 0.0));
  marginal.num_cross = 2;
  EXPECT_FALSE(encodeMessage(marginal).ok());
}

TEST(CoopConvert, InvalidMessagesAreRefused) {
  coop::SharedLandmarks s;
  s.header = {2, 0, 0};
  s.landmarks.push_back({1u, {1, 2, 3}, Eigen::Matrix3d::Identity(), {1, 2}});
  s.landmarks.push_back({2u, {1, 2, 3}, Eigen::Matrix3d::Identity(), {1, 2, 3}});
  Expected<cvslam::shared_landmarks2_t> mixed = toMessage(s);
  ASSERT_TRUE(mixed.ok());
  EXPECT_EQ(mixed->descriptor_length, 0) << "descriptors of different lengths are left out";
  EXPECT_EQ(fromMessage(throughWire(*mixed), 1).landmarks.size(), 2u);
  s.landmarks.pop_back();
  s.landmarks[0].p_LinN.x() = NAN;
  Expected<cvslam::shared_landmarks2_t> m = toMessage(s);
  ASSERT_TRUE(m.ok());  // counts are fine; validation refuses the NaN
  EXPECT_FALSE(encodeMessage(*m).ok());

  coop::CoopSummary sum;
  sum.std = {1, -1, 1};
  Expected<cvslam::agent_summary_t> sm = toMessage(sum);
  ASSERT_TRUE(sm.ok());
  EXPECT_FALSE(encodeMessage(*sm).ok());

  // A count field that lies is refused by decode (validation), not trusted.
  coop::FeatureIndexList l;
  l.indices = {1, 2, 3};
  cvslam::feature_index_t fm = *toMessage(l);
  Expected<std::vector<uint8_t>> bytes = encodeMessage(fm);
  ASSERT_TRUE(bytes.ok());
  std::vector<uint8_t> cut(bytes->begin(), bytes->end() - 4);
  EXPECT_FALSE(decodeMessage<cvslam::feature_index_t>(cut.data(), cut.size()).ok());
  EXPECT_FALSE(decodeMessage<cvslam::shared_landmarks2_t>(bytes->data(), bytes->size()).ok());
}

}  // namespace
}  // namespace cvslam::transport
