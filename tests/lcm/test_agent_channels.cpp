// What cvslam_agent needs from the bus beyond the basics: one subscription to a stream of every
// agent (UAV[0-9]+/INDEX, the only pattern allowed), and bytes published per channel.
#include <gtest/gtest.h>

#include <atomic>
#include <set>

#include "cvslam/io/config_node.h"
#include "cvslam/lcm/agent_node.h"
#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/codec.h"
#include "cvslam/lcm/lcm_bus.h"
#include "lcm_test_util.h"
#include "sample_messages.h"
#include "shipped_config.h"

namespace cvslam::transport {
namespace {

TEST(AgentChannels, PatternsOfPerAgentStreamsOnly) {
  EXPECT_EQ(allAgentsPattern(Stream::kIndex), "UAV[0-9]+/INDEX");
  EXPECT_TRUE(isAgentPattern("UAV[0-9]+/INDEX"));
  EXPECT_TRUE(isAgentPattern("UAV[0-9]+/SHARED_REQ"));
  EXPECT_FALSE(isAgentPattern("UAV.*"));
  EXPECT_FALSE(isAgentPattern("UAV[0-9]+/NOPE"));
  EXPECT_FALSE(isAgentPattern("TEAM/SUMMARY"));
  EXPECT_FALSE(isPlainChannelName(allAgentsPattern(Stream::kIndex)));
}

TEST(AgentChannels, PatternSubscriptionHearsEveryAgentAndCountsBytes) {
  BusOptions o;
  o.url = "memq://";
  auto bus = LcmBus::create(o);
  ASSERT_TRUE(bus.ok());
  std::mutex m;
  std::set<int32_t> senders;
  ASSERT_TRUE((*bus)
                  ->subscribe<cvslam::feature_index_t>(allAgentsPattern(Stream::kIndex),
                                                       [&](const cvslam::feature_index_t& msg) {
                                                         std::lock_guard<std::mutex> l(m);
                                                         senders.insert(msg.header.agent_id);
                                                       })
                  .ok());
  EXPECT_FALSE((*bus)->subscribe<cvslam::imu_t>("UAV.*", [](const cvslam::imu_t&) {}).ok());
  ASSERT_TRUE((*bus)->start().ok());
  int64_t bytes = 0;
  for (int id : {1, 7, 42}) {
    cvslam::feature_index_t msg = testing::sample<cvslam::feature_index_t>();
    msg.header.agent_id = id;
    ASSERT_TRUE((*bus)->publish(channels::index(id), msg).ok());
    auto encoded = encodeMessage(msg);
    ASSERT_TRUE(encoded.ok());
    if (id == 7) bytes = static_cast<int64_t>(encoded->size());
  }
  // Not an INDEX channel: not delivered.
  cvslam::feature_index_t other = testing::sample<cvslam::feature_index_t>();
  other.header.agent_id = 5;
  ASSERT_TRUE((*bus)->publish("UAV5/INDEXX", other).ok());
  ASSERT_TRUE(testing::waitFor([&] {
    std::lock_guard<std::mutex> l(m);
    return senders.size() == 3;
  }));
  std::lock_guard<std::mutex> l(m);
  EXPECT_EQ(senders, (std::set<int32_t>{1, 7, 42}));
  EXPECT_EQ((*bus)->bytesPublished(channels::index(7)), bytes);
  EXPECT_EQ((*bus)->messagesPublished(channels::index(7)), 1);
  EXPECT_EQ((*bus)->bytesPublishedByChannel().size(), 4u);
}

TEST(AgentNodeOptions, ShippedSectionLoadsAndBadValuesFail) {
  auto shipped = test::shippedAgentConfig();
  ASSERT_TRUE(shipped.ok());
  AgentNodeOptions o;
  ASSERT_TRUE(o.load(shipped->child("agent")).ok()) << shipped->status().message();
  EXPECT_DOUBLE_EQ(o.status_period_s, 0.2);
  EXPECT_EQ(o.frame_queue, 64u);
  EXPECT_DOUBLE_EQ(o.initial_sigma.attitude_sigma(0), M_PI / 180.0);
  auto bad = ConfigNode::fromString("max_wait_s: 0\nframe_queue: -3\n", "bad.yaml");
  ASSERT_TRUE(bad.ok());
  Status s = AgentNodeOptions().load(*bad);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("max_wait_s"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace cvslam::transport
