// header_peek: the header of every cvslam type read from its encoding without decoding the
// rest; ChannelStatistics: counts, gaps and resets per sender.

#include <gtest/gtest.h>

#include "cvslam/lcm/channel_monitor.h"
#include "cvslam/lcm/codec.h"
#include "cvslam/lcm/header_peek.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam::transport {
namespace {

template <typename Msg>
void expectPeek(Msg msg, const char* type) {
  msg.header.utime = 1403637132888320;
  msg.header.seq = 123456789012;
  msg.header.agent_id = -1;
  auto bytes = encodeMessage(msg);
  ASSERT_TRUE(bytes.ok()) << bytes.status().message();
  auto h = peekHeader(bytes->data(), bytes->size());
  ASSERT_TRUE(h.has_value()) << type;
  EXPECT_EQ(h->type, type);
  EXPECT_EQ(h->utime, 1403637132888320);
  EXPECT_EQ(h->seq, 123456789012);
  EXPECT_EQ(h->agent_id, -1);
}

TEST(HeaderPeek, ReadsTheHeaderOfEveryType) {
  expectPeek(cvslam::imu_t{}, "imu_t");
  cvslam::pose_t pose{};
  pose.quaternion[0] = 1.0;
  expectPeek(pose, "pose_t");
  cvslam::status_t status{};
  expectPeek(status, "status_t");
  cvslam::stereo_features_t features{};
  expectPeek(features, "stereo_features_t");
  cvslam::stereo_image_t image{};
  image.width = 2;
  image.height = 1;
  image.stride = 2;
  image.left_data = {1, 2};
  image.right_data = {3, 4};
  expectPeek(image, "stereo_image_t");
}

TEST(HeaderPeek, ForeignAndShortBuffersHaveNoHeader) {
  std::vector<uint8_t> junk(64, 0xab);
  EXPECT_FALSE(peekHeader(junk.data(), junk.size()).has_value());
  cvslam::imu_t imu{};
  auto bytes = encodeMessage(imu);
  ASSERT_TRUE(bytes.ok());
  EXPECT_FALSE(peekHeader(bytes->data(), 27).has_value());
}

TEST(ChannelStatistics, CountsGapsPerSenderAndResets) {
  ChannelStatistics stats;
  auto h = [](int32_t agent, int64_t seq) {
    PeekedHeader p;
    p.type = "imu_t";
    p.agent_id = agent;
    p.seq = seq;
    return std::optional<PeekedHeader>(p);
  };
  // Sender 1 starts at seq 5 (we joined late: not a gap), then loses 7 and 8.
  stats.add("UAV1/IMU", 100, h(1, 5), 0.0);
  stats.add("UAV1/IMU", 100, h(1, 6), 0.5);
  stats.add("UAV1/IMU", 100, h(1, 9), 1.0);
  // Sender 2 on the same channel has its own numbering.
  stats.add("UAV1/IMU", 100, h(2, 0), 1.5);
  stats.add("UAV1/IMU", 100, h(2, 1), 2.0);
  stats.add("UAV1/IMU", 100, h(1, 0), 2.0);  // sender 1 restarted
  stats.add("OTHER", 10, std::nullopt, 0.0);
  const auto r = stats.report();
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].channel, "OTHER");
  EXPECT_EQ(r[0].no_header, 1);
  EXPECT_EQ(r[0].type, "?");
  const ChannelReport& imu = r[1];
  EXPECT_EQ(imu.messages, 6);
  EXPECT_EQ(imu.bytes, 600);
  EXPECT_EQ(imu.seq_gaps, 2);
  EXPECT_EQ(imu.seq_resets, 1);
  EXPECT_EQ(imu.senders, 2);
  EXPECT_DOUBLE_EQ(imu.active_s, 2.0);
  EXPECT_DOUBLE_EQ(imu.rate_hz, 2.5);
  EXPECT_DOUBLE_EQ(imu.bandwidth_Bps, 300.0);
}

}  // namespace
}  // namespace cvslam::transport
