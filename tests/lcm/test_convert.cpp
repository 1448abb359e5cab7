// Core struct ↔ LCM message adapters: values survive a full trip through the wire format.

#include <gtest/gtest.h>

#include "cvslam/lcm/codec.h"
#include "cvslam/lcm/features_convert.h"
#include "cvslam/lcm/imu_convert.h"
#include "lcm_test_util.h"

namespace cvslam::transport {
namespace {

using testing::throughWire;

TEST(Convert, ImuSampleRoundTrip) {
  ImuSample s;
  s.t_us = 1403636579758555;
  s.gyro_B = Eigen::Vector3d(0.01, -0.02, 0.3);
  s.accel_B = Eigen::Vector3d(0.1, 0.2, -9.81);
  const cvslam::imu_t msg = throughWire(toMessage(s, 3));
  EXPECT_EQ(msg.header.agent_id, 3);
  const ImuSample back = fromMessage(msg);
  EXPECT_EQ(back.t_us, s.t_us);
  EXPECT_EQ(back.gyro_B, s.gyro_B);
  EXPECT_EQ(back.accel_B, s.accel_B);
}

TEST(Convert, StereoObservationsRoundTripIncludingLargeIndices) {
  StereoFrameObservations frame;
  frame.t_us = 42;
  for (uint32_t i = 0; i < 3; ++i) {
    StereoObservation o;
    o.index = 0xfffffff0u + i;  // above INT32_MAX: travels as a bit pattern
    o.z = Eigen::Vector4d(100.5 + i, 200.25, 90.5 + i, 200.25);
    o.descriptor = {static_cast<uint8_t>(i), 1, 2, 3};
    frame.observations.push_back(o);
  }
  Expected<cvslam::stereo_features_t> msg = toMessage(frame, 1);
  ASSERT_TRUE(msg.ok()) << msg.status().message();
  EXPECT_EQ(msg->num_features, 3);
  EXPECT_EQ(msg->descriptor_length, 4);
  const StereoFrameObservations back = fromMessage(throughWire(*msg));
  EXPECT_EQ(back.t_us, 42);
  ASSERT_EQ(back.observations.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.observations[i].index, frame.observations[i].index);
    EXPECT_EQ(back.observations[i].z, frame.observations[i].z);
    EXPECT_EQ(back.observations[i].descriptor, frame.observations[i].descriptor);
    EXPECT_EQ(back.observations[i].type, ObservationType::kNew);
    EXPECT_EQ(back.observations[i].landmark_id, -1);
  }
}

TEST(Convert, StereoObservationsWithMixedDescriptorLengthsAreRefused) {
  StereoFrameObservations frame;
  frame.observations.resize(2);
  frame.observations[0].descriptor = {1, 2};
  frame.observations[1].descriptor = {1, 2, 3};
  EXPECT_FALSE(toMessage(frame, 1).ok());
}

}  // namespace
}  // namespace cvslam::transport
