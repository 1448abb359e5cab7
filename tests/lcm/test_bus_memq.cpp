// LcmBus in one process over memq://: typed publish/subscribe, sequence stamping,
// queues and callbacks, counters for drops, invalid messages, unknown agents and gaps.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <vector>

#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/lcm_bus.h"
#include "lcm_test_util.h"
#include "sample_messages.h"

namespace cvslam::transport {
namespace {

using std::chrono::milliseconds;
using testing::sample;
using testing::waitFor;

std::unique_ptr<LcmBus> makeBus(BusOptions options = {}) {
  options.url = "memq://";
  Expected<std::unique_ptr<LcmBus>> bus = LcmBus::create(std::move(options));
  EXPECT_TRUE(bus.ok()) << bus.status().message();
  return bus.ok() ? std::move(bus.value()) : nullptr;
}

TEST(LcmBusMemq, QueueSubscriptionDeliversInOrderWithStampedSeq) {
  auto bus = makeBus();
  ASSERT_TRUE(bus);
  auto queue = bus->subscribeQueue<cvslam::imu_t>(channels::imu(1), 100);
  ASSERT_TRUE(queue.ok());
  ASSERT_TRUE(bus->start().ok());
  for (int i = 0; i < 20; ++i) {
    cvslam::imu_t m = sample<cvslam::imu_t>();
    m.header.utime = 1000 + i;
    m.header.agent_id = 1;
    ASSERT_TRUE(bus->publish(channels::imu(1), m).ok());
    EXPECT_EQ(m.header.seq, i) << "publish stamps the per-channel sequence number";
  }
  for (int i = 0; i < 20; ++i) {
    auto m = (*queue)->pop(milliseconds(2000));
    ASSERT_TRUE(m.has_value()) << "message " << i;
    EXPECT_EQ(m->header.seq, i);
    EXPECT_EQ(m->header.utime, 1000 + i);
    EXPECT_DOUBLE_EQ(m->accel[2], -9.81);
  }
  // The counter is bumped just after the push, so it may trail the queue briefly.
  EXPECT_TRUE(waitFor([&] { return bus->counters(channels::imu(1)).received == 20; }));
  const ChannelCounters c = bus->counters(channels::imu(1));
  EXPECT_EQ(c.received, 20);
  EXPECT_EQ(c.dropped, 0);
  EXPECT_EQ(c.invalid, 0);
  EXPECT_EQ(c.seq_gaps, 0);
  EXPECT_EQ(c.type, "imu_t");
}

TEST(LcmBusMemq, SequenceNumbersAreIndependentPerChannel) {
  auto bus = makeBus();
  ASSERT_TRUE(bus);
  cvslam::status_t s = sample<cvslam::status_t>();
  cvslam::imu_t m = sample<cvslam::imu_t>();
  ASSERT_TRUE(bus->publish(channels::status(1), s).ok());
  ASSERT_TRUE(bus->publish(channels::status(1), s).ok());
  ASSERT_TRUE(bus->publish(channels::imu(1), m).ok());
  EXPECT_EQ(s.header.seq, 1);
  EXPECT_EQ(m.header.seq, 0);
}

TEST(LcmBusMemq, CallbackRunsOnTheReceiveThread) {
  auto bus = makeBus();
  ASSERT_TRUE(bus);
  std::mutex mutex;
  std::vector<int64_t> versions;
  std::thread::id callback_thread;
  ASSERT_TRUE(bus->subscribe<cvslam::map_t>(channels::gsMap(),
                                            [&](const cvslam::map_t& m) {
                                              std::lock_guard<std::mutex> lock(mutex);
                                              versions.push_back(m.map_version);
                                              callback_thread = std::this_thread::get_id();
                                            })
                  .ok());
  ASSERT_TRUE(bus->start().ok());
  for (int v = 0; v < 5; ++v) {
    cvslam::map_t m = sample<cvslam::map_t>();
    m.map_version = v;
    ASSERT_TRUE(bus->publish(channels::gsMap(), m).ok());
  }
  ASSERT_TRUE(waitFor([&] { return bus->counters(channels::gsMap()).received == 5; }));
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(versions, (std::vector<int64_t>{0, 1, 2, 3, 4}));
  EXPECT_NE(callback_thread, std::this_thread::get_id());
}

TEST(LcmBusMemq, FullQueueDropsTheNewestAndCountsIt) {
  auto bus = makeBus();
  ASSERT_TRUE(bus);
  auto queue = bus->subscribeQueue<cvslam::pose_t>(channels::groundTruth(1), 3);
  ASSERT_TRUE(queue.ok());
  ASSERT_TRUE(bus->start().ok());
  for (int i = 0; i < 10; ++i) {
    cvslam::pose_t m = sample<cvslam::pose_t>();
    m.header.utime = i;
    ASSERT_TRUE(bus->publish(channels::groundTruth(1), m).ok());
  }
  ASSERT_TRUE(waitFor([&] {
    const ChannelCounters c = bus->counters(channels::groundTruth(1));
    return c.received + c.dropped == 10;
  }));
  const ChannelCounters c = bus->counters(channels::groundTruth(1));
  EXPECT_EQ(c.received, 3);
  EXPECT_EQ(c.dropped, 7);
  for (int i = 0; i < 3; ++i) EXPECT_EQ((*queue)->tryPop()->header.utime, i) << "oldest kept";
  EXPECT_FALSE((*queue)->tryPop().has_value());
}

TEST(LcmBusMemq, InvalidBuffersAndUnknownAgentsAreCountedAndReported) {
  std::mutex mutex;
  std::vector<std::string> errors;
  BusOptions options;
  options.receive.accept_agent = acceptOnly({1, 2});
  options.receive.on_error = [&](const std::string& channel, const Status& error) {
    std::lock_guard<std::mutex> lock(mutex);
    errors.push_back(channel + ": " + error.message());
  };
  auto bus = makeBus(options);
  ASSERT_TRUE(bus);
  auto queue = bus->subscribeQueue<cvslam::imu_t>(channels::imu(1), 10);
  ASSERT_TRUE(queue.ok());
  ASSERT_TRUE(bus->start().ok());

  std::vector<uint8_t> good = testing::encodedSample<cvslam::imu_t>();  // agent 2
  ASSERT_TRUE(bus->publishRaw(channels::imu(1), good.data(), good.size()).ok());
  std::vector<uint8_t> truncated(good.begin(), good.end() - 1);
  ASSERT_TRUE(bus->publishRaw(channels::imu(1), truncated.data(), truncated.size()).ok());
  std::vector<uint8_t> pose = testing::encodedSample<cvslam::pose_t>();
  ASSERT_TRUE(bus->publishRaw(channels::imu(1), pose.data(), pose.size()).ok());
  cvslam::imu_t stranger = sample<cvslam::imu_t>();
  stranger.header.agent_id = 9;
  std::vector<uint8_t> from9 = testing::rawEncode(stranger);
  ASSERT_TRUE(bus->publishRaw(channels::imu(1), from9.data(), from9.size()).ok());

  ASSERT_TRUE(waitFor([&] {
    const ChannelCounters c = bus->counters(channels::imu(1));
    return c.received + c.invalid == 4;
  }));
  const ChannelCounters c = bus->counters(channels::imu(1));
  EXPECT_EQ(c.received, 1);
  EXPECT_EQ(c.invalid, 3);
  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_EQ(errors.size(), 3u);
  EXPECT_NE(errors[0].find("UAV1/IMU"), std::string::npos);
  EXPECT_NE(errors[1].find("fingerprint"), std::string::npos) << errors[1];
  EXPECT_NE(errors[2].find("agent 9"), std::string::npos) << errors[2];
}

TEST(LcmBusMemq, SequenceGapsAreCountedPerSender) {
  auto bus = makeBus();
  ASSERT_TRUE(bus);
  auto queue = bus->subscribeQueue<cvslam::agent_summary_t>(channels::teamSummary(), 100);
  ASSERT_TRUE(queue.ok());
  ASSERT_TRUE(bus->start().ok());
  // Agent 1 sends 0,1,4 (2 missing); agent 2 sends 0,1,2 (none missing), interleaved.
  const std::pair<int32_t, int64_t> sends[] = {{1, 0}, {2, 0}, {1, 1}, {2, 1}, {1, 4}, {2, 2}};
  for (const auto& [agent, seq] : sends) {
    cvslam::agent_summary_t m = sample<cvslam::agent_summary_t>();
    m.header.agent_id = agent;
    m.header.seq = seq;
    std::vector<uint8_t> b = testing::rawEncode(m);
    ASSERT_TRUE(bus->publishRaw(channels::teamSummary(), b.data(), b.size()).ok());
  }
  ASSERT_TRUE(waitFor([&] { return bus->counters(channels::teamSummary()).received == 6; }));
  EXPECT_EQ(bus->counters(channels::teamSummary()).seq_gaps, 2);
  EXPECT_EQ(bus->counters(channels::teamSummary()).seq_resets, 0);
}

TEST(LcmBusMemq, RefusesBadChannelsLateSubscriptionsAndInvalidMessages) {
  auto bus = makeBus();
  ASSERT_TRUE(bus);
  EXPECT_FALSE(bus->subscribeQueue<cvslam::imu_t>("UAV.*/IMU", 10).ok());
  cvslam::imu_t m = sample<cvslam::imu_t>();
  EXPECT_FALSE(bus->publish("UAV1/IMU?", m).ok());
  m.gyro[0] = std::nan("");
  EXPECT_FALSE(bus->publish(channels::imu(1), m).ok());
  ASSERT_TRUE(bus->start().ok());
  EXPECT_TRUE(bus->running());
  EXPECT_FALSE(bus->subscribeQueue<cvslam::imu_t>(channels::imu(2), 10).ok());
  bus->stop();
  EXPECT_FALSE(bus->running());
}

TEST(LcmBusMemq, BadUrlIsAnErrorNotACrash) {
  BusOptions options;
  options.url = "nosuchprovider://x";
  EXPECT_FALSE(LcmBus::create(options).ok());
}

TEST(LcmBusMemq, TwoBusesInOneProcessAreIndependent) {
  // No global state: several agents must coexist in one test process.
  auto a = makeBus();
  auto b = makeBus();
  ASSERT_TRUE(a && b);
  auto qa = a->subscribeQueue<cvslam::status_t>(channels::status(1), 10);
  auto qb = b->subscribeQueue<cvslam::status_t>(channels::status(1), 10);
  ASSERT_TRUE(qa.ok() && qb.ok());
  ASSERT_TRUE(a->start().ok() && b->start().ok());
  cvslam::status_t s = sample<cvslam::status_t>();
  ASSERT_TRUE(a->publish(channels::status(1), s).ok());
  EXPECT_TRUE((*qa)->pop(milliseconds(2000)).has_value());
  EXPECT_FALSE((*qb)->pop(milliseconds(200)).has_value()) << "memq:// is per LCM instance";
}

}  // namespace
}  // namespace cvslam::transport
