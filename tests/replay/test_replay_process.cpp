// cvslam_replay as a real process over loopback multicast, each test on its own port
// (docs/architecture.md): every message arrives, in order, with the dataset's timestamps; lockstep
// waits for the subscribers' STATUS; bad datasets give one clear line and status 2.

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <mutex>

#include "cvslam/dataset/euroc_dataset.h"
#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/lcm_bus.h"
#include "cvslam/lcm/sensor_convert.h"
#include "euroc_test_folder.h"
#include "lcm/lcm_test_util.h"
#include "process_util.h"
#include "small_scenario.h"

namespace cvslam {
namespace {

using transport::channels::groundTruth;
using transport::channels::imu;
using transport::channels::stereo;

std::string url(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=16777216";
}

std::string simulateDataset(const test::TempFolder& tmp, double duration) {
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", duration, true);
  std::string err;
  EXPECT_EQ(
      test::run({CVSLAM_SIMULATE_EXE, "--quiet", "--scenario", scenario, "--out", tmp / "data"},
                tmp / "sim", nullptr, &err),
      0)
      << err;
  return tmp / "data";
}

template <typename Msg>
std::vector<Msg> drain(transport::BoundedQueue<Msg>& q) {
  std::vector<Msg> out;
  while (std::optional<Msg> m = q.tryPop()) out.push_back(std::move(*m));
  return out;
}

void replayAndCheck(bool compress, int port) {
  test::TempFolder tmp;
  const std::string data = simulateDataset(tmp, 1.0);
  transport::BusOptions o;
  o.url = url(port);
  auto bus = transport::LcmBus::create(o);
  ASSERT_TRUE(bus.ok()) << bus.status().message();
  std::map<int, std::shared_ptr<transport::BoundedQueue<cvslam::imu_t>>> imu_q;
  std::map<int, std::shared_ptr<transport::BoundedQueue<cvslam::pose_t>>> gt_q;
  std::map<int, std::shared_ptr<transport::BoundedQueue<cvslam::stereo_image_t>>> st_q;
  for (int id : {1, 2}) {
    imu_q[id] = *(*bus)->subscribeQueue<cvslam::imu_t>(imu(id), 10000);
    gt_q[id] = *(*bus)->subscribeQueue<cvslam::pose_t>(groundTruth(id), 10000);
    st_q[id] = *(*bus)->subscribeQueue<cvslam::stereo_image_t>(stereo(id), 100);
  }
  ASSERT_TRUE((*bus)->start().ok());
  std::vector<std::string> args = {
      CVSLAM_REPLAY_EXE,     "--quiet", "--dataset", "1:" + data + "/uav1", "--dataset",
      "2:" + data + "/uav2", "--rate",  "2",         "--lcm-url",           url(port)};
  if (compress) args.push_back("--compress");
  std::string err;
  ASSERT_EQ(test::run(args, tmp / "replay", nullptr, &err), 0) << err;
  for (int id : {1, 2}) {
    SCOPED_TRACE(id);
    auto d = EurocDataset::open(data + "/uav" + std::to_string(id));
    ASSERT_TRUE(d.ok());
    ASSERT_TRUE(transport::testing::waitFor([&] {
      return (*bus)->counters(stereo(id)).received == static_cast<int64_t>(d->frameCount()) &&
             (*bus)->counters(imu(id)).received == static_cast<int64_t>(d->imu().size());
    })) << "imu "
        << (*bus)->counters(imu(id)).received << " stereo "
        << (*bus)->counters(stereo(id)).received;
    const auto imus = drain(*imu_q[id]);
    ASSERT_EQ(imus.size(), d->imu().size());
    for (std::size_t i = 0; i < imus.size(); ++i) {
      EXPECT_EQ(imus[i].header.seq, static_cast<int64_t>(i));  // in order, none lost
      EXPECT_EQ(imus[i].header.utime, d->imu()[i].t_us);
      EXPECT_EQ(imus[i].header.agent_id, transport::kReplaySenderId);
      EXPECT_EQ(imus[i].accel[2], d->imu()[i].accel_B.z());
    }
    const auto gts = drain(*gt_q[id]);
    ASSERT_EQ(gts.size(), d->groundTruth().size());
    for (std::size_t i = 0; i < gts.size(); ++i) {
      EXPECT_EQ(gts[i].header.seq, static_cast<int64_t>(i));
      EXPECT_EQ(gts[i].header.utime * 1000, d->groundTruth()[i].t_ns);
      EXPECT_EQ(gts[i].position[0], d->groundTruth()[i].p_SinR.x());
    }
    const auto frames = drain(*st_q[id]);
    ASSERT_EQ(frames.size(), d->frameCount());
    for (std::size_t i = 0; i < frames.size(); ++i) {
      EXPECT_EQ(frames[i].header.seq, static_cast<int64_t>(i));
      EXPECT_EQ(frames[i].header.utime * 1000, d->frameTimeNs(i));
      EXPECT_EQ(frames[i].encoding, compress ? cvslam::stereo_image_t::ENCODING_PNG
                                             : cvslam::stereo_image_t::ENCODING_MONO8);
      cv::Mat left, right;
      ASSERT_TRUE(transport::fromStereoMessage(frames[i], left, right).ok());
      auto f = d->loadFrame(i);
      ASSERT_TRUE(f.ok());
      EXPECT_EQ(cv::norm(left, f->left, cv::NORM_INF), 0.0);
      EXPECT_EQ(cv::norm(right, f->right, cv::NORM_INF), 0.0);
    }
  }
}

TEST(ReplayProcess, DeliversEveryMessageInOrderMono8) {
  replayAndCheck(false, 27761);
}
TEST(ReplayProcess, DeliversEveryMessageInOrderPng) {
  replayAndCheck(true, 27762);
}

// A test subscriber plays two agents: it announces itself on UAV1/STATUS and UAV2/STATUS,
// and acknowledges each agent's frame some milliseconds after receiving it. The replay must
// never send anything of the next epoch before both acknowledged the current one.
TEST(ReplayProcess, LockstepWaitsForEveryStatus) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 1.0, true);
  const int port = 27763;
  transport::BusOptions o;
  o.url = url(port);
  auto bus = transport::LcmBus::create(o);
  ASSERT_TRUE(bus.ok());
  std::mutex mutex;
  std::map<int, int64_t> acked = {{1, -100000}, {2, -100000}};  // last acknowledged frame
  std::vector<std::pair<int, int64_t>> to_ack;                  // frames received, not acked
  std::atomic<int> violations{0}, messages{0}, frames{0};
  auto check = [&](int64_t utime) {
    std::lock_guard<std::mutex> guard(mutex);
    const int64_t allowed = std::min(acked[1], acked[2]) + 100000;  // 10 Hz frames
    if (utime > allowed) ++violations;
    ++messages;
  };
  for (int id : {1, 2}) {
    ASSERT_TRUE((*bus)
                    ->subscribe<cvslam::imu_t>(
                        imu(id), [&](const cvslam::imu_t& m) { check(m.header.utime); })
                    .ok());
    ASSERT_TRUE(
        (*bus)
            ->subscribe<cvslam::stereo_features_t>(transport::channels::features(id),
                                                   [&, id](const cvslam::stereo_features_t& m) {
                                                     check(m.header.utime);
                                                     std::lock_guard<std::mutex> guard(mutex);
                                                     to_ack.emplace_back(id, m.header.utime);
                                                     ++frames;
                                                   })
            .ok());
  }
  ASSERT_TRUE((*bus)->start().ok());
  test::Child replay({CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features",
                      "--lockstep", "--lockstep-timeout", "10", "--lcm-url", url(port)},
                     tmp / "replay");
  ASSERT_TRUE(replay.started());
  auto publishStatus = [&](int id, int64_t processed) {
    cvslam::status_t s{};
    s.header.utime = processed;
    s.header.agent_id = id;
    s.processed_utime = processed;
    s.health = cvslam::status_t::HEALTH_OK;
    ASSERT_TRUE((*bus)->publish(transport::channels::status(id), s).ok());
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(25);
  int status = -2;
  while (std::chrono::steady_clock::now() < deadline) {
    if (messages == 0) {  // announce until the replay has seen us
      publishStatus(1, -1);
      publishStatus(2, -1);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    std::vector<std::pair<int, int64_t>> pending;
    {
      std::lock_guard<std::mutex> guard(mutex);
      pending.swap(to_ack);
    }
    for (const auto& [id, t] : pending) {
      std::this_thread::sleep_for(std::chrono::milliseconds(3));  // "processing"
      {
        std::lock_guard<std::mutex> guard(mutex);
        acked[id] = t;
      }
      publishStatus(id, t);
    }
    if (replay.exited()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  status = replay.wait(std::chrono::seconds(2));
  EXPECT_EQ(status, 0) << replay.err();
  EXPECT_EQ(violations, 0) << "messages of a later epoch before the acknowledgement";
  EXPECT_EQ(frames, 2 * 11);
  EXPECT_EQ(messages, 2 * (201 + 11));
  EXPECT_NE(replay.err().find("11 epochs"), std::string::npos) << replay.err();
}

TEST(ReplayProcess, LockstepTimesOutNamingTheSilentParticipant) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 0.5, true);
  std::string err;
  EXPECT_EQ(
      test::run({CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features", "--lockstep",
                 "--participants", "2", "--lockstep-timeout", "0.5", "--lcm-url", url(27764)},
                tmp / "r", nullptr, &err),
      2);
  EXPECT_NE(err.find("no acknowledgement"), std::string::npos) << err;
  EXPECT_NE(err.find("UAV2/STATUS"), std::string::npos) << err;
}

TEST(ReplayProcess, BadDatasetsGiveOneLineAndStatus2) {
  test::TempFolder tmp;
  const std::string data = simulateDataset(tmp, 0.2);
  std::string err;
  const std::string u = url(27765);
  EXPECT_EQ(test::run({CVSLAM_REPLAY_EXE, "--dataset", "1:" + tmp / "nowhere", "--lcm-url", u},
                      tmp / "a", nullptr, &err),
            2);
  EXPECT_NE(err.find("nowhere"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;

  std::filesystem::remove(data + "/uav1/mav0/imu0/data.csv");
  EXPECT_EQ(test::run({CVSLAM_REPLAY_EXE, "--dataset", "1:" + data + "/uav1", "--lcm-url", u},
                      tmp / "b", nullptr, &err),
            2);
  EXPECT_NE(err.find("imu0/data.csv"), std::string::npos) << err;

  std::ofstream(data + "/uav2/mav0/cam0/data.csv", std::ios::app) << "12,missing.png\n";
  EXPECT_EQ(test::run({CVSLAM_REPLAY_EXE, "--dataset", "2:" + data + "/uav2", "--lcm-url", u},
                      tmp / "c", nullptr, &err),
            2);
  EXPECT_NE(err.find("cam0"), std::string::npos) << err;

  for (const auto& bad : std::vector<std::vector<std::string>>{
           {"--dataset", "x:" + data},
           {"--dataset", "1:" + data, "--dataset", "1:" + data},
           {"--dataset", "1:" + data, "--lockstep", "--rate", "2"},
           {},
           {"--scenario", "a.yaml", "--dataset", "1:" + data},
           {"--dataset", "1:" + data, "--bogus"}}) {
    std::vector<std::string> args = {CVSLAM_REPLAY_EXE};
    args.insert(args.end(), bad.begin(), bad.end());
    EXPECT_EQ(test::run(args, tmp / "d", nullptr, &err), 2) << args.size();
    EXPECT_EQ(err.rfind("cvslam_replay: ", 0), 0u) << err;
  }
  std::string out;
  EXPECT_EQ(test::run({CVSLAM_REPLAY_EXE, "--help"}, tmp / "h", &out), 0);
  EXPECT_NE(out.find("usage: cvslam_replay"), std::string::npos);
}

TEST(ReplayProcess, SigintStopsCleanly) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 30.0, true);
  test::Child replay({CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features", "--rate",
                      "1", "--lcm-url", url(27766)},
                     tmp / "r");
  ASSERT_TRUE(replay.started());
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  kill(replay.pid(), SIGINT);
  EXPECT_EQ(replay.wait(std::chrono::seconds(3)), 0) << replay.err();
  EXPECT_NE(replay.err().find("stopped after"), std::string::npos) << replay.err();
}

}  // namespace
}  // namespace cvslam
