// Two processes over real loopback multicast: cvslam_lcm_test_peer publishes ≥ 1000 mixed
// messages (IMU at 200 Hz, 2 × 300 KB stereo images and ground truth at 20 Hz) and this
// process must receive every one, intact and in order. Each test has its own port so
// ctest -j can run the suites in parallel (docs/architecture.md).

#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/lcm_bus.h"
#include "lcm_test_util.h"

extern char** environ;

namespace cvslam::transport {
namespace {

// Our own ports; recv_buf_size lets the kernel hold ~25 stereo pairs if this process lags.
constexpr const char* kUrl = "udpm://239.255.76.67:27701?ttl=0&recv_buf_size=16777216";
constexpr const char* kHostileUrl = "udpm://239.255.76.67:27703?ttl=0&recv_buf_size=16777216";

/// A child process started with posix_spawn; killed (by pid) if still running at the end.
class ChildProcess {
 public:
  explicit ChildProcess(const std::vector<std::string>& args) {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, argv[0], nullptr, nullptr, argv.data(), environ) != 0) pid_ = -1;
  }
  ~ChildProcess() {
    if (pid_ > 0 && !exited_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  bool started() const { return pid_ > 0; }
  /// Waits for the exit; returns the exit status, or -1 on timeout or abnormal end.
  int wait(std::chrono::seconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    int status = 0;
    while (std::chrono::steady_clock::now() < deadline) {
      const pid_t r = waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        exited_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return -1;
  }

 private:
  pid_t pid_ = -1;
  bool exited_ = false;
};

struct Arrival {
  std::string channel;
  int64_t seq;
  int64_t utime;
};

TEST(LcmMultiProcess, ReceivesEveryMixedMessageInOrderFromAnotherProcess) {
  constexpr int kAgent = 3;
  constexpr int kSeconds = 5, kImuHz = 200, kImageHz = 20;
  constexpr int kImu = kSeconds * kImuHz, kImages = kSeconds * kImageHz;

  BusOptions options;
  options.url = kUrl;
  options.receive.accept_agent = acceptOnly({kAgent});
  Expected<std::unique_ptr<LcmBus>> created = LcmBus::create(options);
  ASSERT_TRUE(created.ok()) << created.status().message() << " (run scripts/setup.sh)";
  LcmBus& bus = **created;

  std::mutex mutex;
  std::vector<Arrival> arrivals;
  int64_t bad_images = 0;
  auto record = [&](const std::string& channel, const cvslam::header_t& h) {
    std::lock_guard<std::mutex> lock(mutex);
    arrivals.push_back({channel, h.seq, h.utime});
  };
  ASSERT_TRUE(bus.subscribe<cvslam::imu_t>(
                     channels::imu(kAgent),
                     [&](const cvslam::imu_t& m) { record(channels::imu(kAgent), m.header); })
                  .ok());
  ASSERT_TRUE(bus.subscribe<cvslam::stereo_image_t>(
                     channels::stereo(kAgent),
                     [&](const cvslam::stereo_image_t& m) {
                       // Content check: byte i of the left image is (seq + i) mod 256.
                       bool intact = m.left_data.size() == 752u * 400u && m.width == 752;
                       for (std::size_t i = 0; intact && i < m.left_data.size(); i += 997) {
                         intact = m.left_data[i] == static_cast<uint8_t>(m.header.seq + i) &&
                                  m.right_data[i] == static_cast<uint8_t>(m.header.seq + i + 1);
                       }
                       if (!intact) ++bad_images;
                       record(channels::stereo(kAgent), m.header);
                     })
                  .ok());
  ASSERT_TRUE(bus.subscribe<cvslam::pose_t>(channels::groundTruth(kAgent),
                                            [&](const cvslam::pose_t& m) {
                                              record(channels::groundTruth(kAgent), m.header);
                                            })
                  .ok());
  ASSERT_TRUE(bus.subscribe<cvslam::status_t>(
                     channels::status(kAgent),
                     [&](const cvslam::status_t& m) { record(channels::status(kAgent), m.header); })
                  .ok());
  ASSERT_TRUE(bus.start().ok());

  const auto t0 = std::chrono::steady_clock::now();
  ChildProcess peer({CVSLAM_LCM_TEST_PEER, "stream", "--url", kUrl, "--agent",
                     std::to_string(kAgent), "--seconds", std::to_string(kSeconds), "--imu-hz",
                     std::to_string(kImuHz), "--image-hz", std::to_string(kImageHz)});
  ASSERT_TRUE(peer.started()) << CVSLAM_LCM_TEST_PEER;
  ASSERT_EQ(peer.wait(std::chrono::seconds(25)), 0) << "peer failed or timed out";
  const bool all = testing::waitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return arrivals.size() >= static_cast<std::size_t>(kImu + 2 * kImages + 1);
      },
      std::chrono::milliseconds(10000));
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  bus.stop();

  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_TRUE(all) << "received " << arrivals.size();
  EXPECT_EQ(bad_images, 0);
  // Per channel: every sequence number exactly once, in order.
  std::map<std::string, int64_t> next;
  int64_t last_utime = 0;
  for (const Arrival& a : arrivals) {
    EXPECT_EQ(a.seq, next[a.channel]++) << a.channel;
    EXPECT_GE(a.utime, last_utime) << "global dataset-time order, " << a.channel;
    last_utime = a.utime;
  }
  EXPECT_EQ(next[channels::imu(kAgent)], kImu);
  EXPECT_EQ(next[channels::stereo(kAgent)], kImages);
  EXPECT_EQ(next[channels::groundTruth(kAgent)], kImages);
  EXPECT_EQ(next[channels::status(kAgent)], 1);
  for (const ChannelCounters& c : bus.counters()) {
    EXPECT_EQ(c.dropped, 0) << c.channel;
    EXPECT_EQ(c.invalid, 0) << c.channel;
    EXPECT_EQ(c.seq_gaps, 0) << c.channel;
  }
  std::printf("[ figures  ] %zu messages (%d stereo pairs of 2 x 300800 B) in %.2f s\n",
              arrivals.size(), kImages, elapsed);
}

TEST(LcmMultiProcess, JunkAndUnknownSendersFromAnotherProcessAreCountedNotDelivered) {
  constexpr int kAgent = 4, kRounds = 100;
  BusOptions options;
  options.url = kHostileUrl;
  options.receive.accept_agent = acceptOnly({kAgent});
  Expected<std::unique_ptr<LcmBus>> created = LcmBus::create(options);
  ASSERT_TRUE(created.ok()) << created.status().message() << " (run scripts/setup.sh)";
  LcmBus& bus = **created;
  auto queue = bus.subscribeQueue<cvslam::imu_t>(channels::imu(kAgent), 1000);
  ASSERT_TRUE(queue.ok());
  ASSERT_TRUE(bus.start().ok());

  ChildProcess peer(
      {CVSLAM_LCM_TEST_PEER, "hostile", "--url", kHostileUrl, "--agent", std::to_string(kAgent)});
  ASSERT_TRUE(peer.started());
  ASSERT_EQ(peer.wait(std::chrono::seconds(20)), 0);
  EXPECT_TRUE(testing::waitFor(
      [&] {
        const ChannelCounters c = bus.counters(channels::imu(kAgent));
        return c.received + c.invalid >= 3 * kRounds;
      },
      std::chrono::milliseconds(10000)));
  bus.stop();
  const ChannelCounters c = bus.counters(channels::imu(kAgent));
  EXPECT_EQ(c.received, kRounds);
  EXPECT_EQ(c.invalid, 2 * kRounds);
  EXPECT_EQ(c.seq_gaps, 0) << "the valid sender's sequence is complete";
  for (int k = 0; k < kRounds; ++k) {
    auto m = (*queue)->tryPop();
    ASSERT_TRUE(m.has_value());
    EXPECT_EQ(m->header.agent_id, kAgent);
    EXPECT_EQ(m->header.utime, 1000 * k);
  }
}

}  // namespace
}  // namespace cvslam::transport
