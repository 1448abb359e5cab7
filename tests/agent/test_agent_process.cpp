// cvslam_agent as real processes with cvslam_replay over loopback multicast (docs/architecture.md
// §6, §7): a lockstep run reproduces cvslam_run; agents survive a peer's death and its
// restart; floods of junk are counted, never fatal; bad command lines fail in one line.
// Ports 27800–27849 (docs/agent.md), one per test.
#include <gtest/gtest.h>
#include <signal.h>

#include <fstream>
#include <random>
#include <thread>

#include "agent_test_util.h"
#include "cvslam/lcm/codec.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam {
namespace {

using namespace std::chrono_literals;

bool validRecord(const std::string& run, int id, std::size_t min_poses) {
  const std::string dir = run + "/agent_" + std::to_string(id);
  const std::size_t poses = test::poseCount(dir + "/trajectory.tum");
  auto stats = readJsonFile(dir + "/stats.json");
  return poses >= min_poses && stats.ok() && std::filesystem::exists(dir + "/landmarks.csv");
}

TEST(AgentProcess, LockstepReproducesCvslamRun) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 12.0, true);
  std::string err;
  ASSERT_EQ(test::run({CVSLAM_RUN_EXE, "--scenario", scenario, "--sensing", "features", "--out",
                       tmp / "inproc", "--quiet"},
                      tmp / "run", nullptr, &err),
            0)
      << err;
  const std::string url = test::agentUrl(27800);
  test::Child a1(test::agentArgs(1, scenario, url, tmp / "lcm"), tmp / "a1");
  test::Child a2(test::agentArgs(2, scenario, url, tmp / "lcm"), tmp / "a2");
  test::Child replay({CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features",
                      "--lockstep", "--lockstep-timeout", "20", "--lcm-url", url, "--quiet"},
                     tmp / "replay");
  EXPECT_EQ(replay.wait(90s), 0) << replay.err();
  EXPECT_EQ(a1.wait(30s), 0) << a1.err();
  EXPECT_EQ(a2.wait(30s), 0) << a2.err();
  const auto expected = test::ateOf(tmp / "inproc", tmp / "eval_inproc");
  const auto got = test::ateOf(tmp / "lcm", tmp / "eval_lcm");
  ASSERT_EQ(expected.size(), 2u);
  ASSERT_EQ(got.size(), 2u) << a1.out() << a2.out();
  for (int id : {1, 2}) {
    EXPECT_NEAR(got.at(id), expected.at(id), 0.01 * expected.at(id)) << "UAV" << id;
    EXPECT_LT(got.at(id), 2.0);  // a sane estimate (INS alone drifts far more)
  }
  // Same frames, same estimates: trajectories, dead reckoning, filter events and the map
  // (with the true landmark positions) are identical.
  for (int id : {1, 2}) {
    for (const char* file :
         {"trajectory.tum", "ins_trajectory.tum", "events.csv", "landmarks.csv", "states.csv"}) {
      std::ifstream a(tmp / ("inproc/agent_" + std::to_string(id) + "/" + file));
      std::ifstream b(tmp / ("lcm/agent_" + std::to_string(id) + "/" + file));
      std::stringstream sa, sb;
      sa << a.rdbuf();
      sb << b.rdbuf();
      EXPECT_FALSE(sa.str().empty()) << file;
      EXPECT_EQ(sa.str(), sb.str()) << "UAV" << id << " " << file;
    }
  }
  // Nothing lost on the way; latency reported per frame.
  EXPECT_NE(a1.out().find("messages dropped 0, seq gaps 0, invalid 0, late 0"), std::string::npos)
      << a1.out();
  auto stats = readJsonFile(tmp / "lcm/agent_1/stats.json");
  ASSERT_TRUE(stats.ok());
  EXPECT_TRUE(stats->at("frames").contains("latency_ms"));
  EXPECT_TRUE(stats->contains("bytes_sent_per_s"));
}

TEST(AgentProcess, PeersSurviveAKilledAgentWhichRejoins) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 20.0, true);
  const std::string url = test::agentUrl(27801);
  test::SummaryListener listener(url);
  ASSERT_TRUE(listener.ok());
  test::StatusListener status(url);
  ASSERT_TRUE(status.ok());
  // DC mode: the survivor also cooperates with the peer before and after its restart.
  test::Child a1(test::agentArgs(1, scenario, url, tmp / "lcm", "dc"), tmp / "a1");
  auto a2 = std::make_unique<test::Child>(test::agentArgs(2, scenario, url, tmp / "lcm", "dc"),
                                          tmp / "a2");
  std::this_thread::sleep_for(500ms);  // subscribed
  test::Child replay({CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features", "--rate",
                      "4", "--lcm-url", url, "--quiet"},
                     tmp / "replay");
  // Synchronised on events, not on sleeps: UAV 1 knows UAV 2; UAV 2 is killed; UAV 1 times it
  // out (peer_timeout_s of data time without a word); only then does UAV 2 come back.
  ASSERT_TRUE(status.waitFor(1, "peers 2;", 30s)) << status.last(1);
  ASSERT_EQ(listener.bootIds(2).size(), 1u);
  kill(a2->pid(), SIGKILL);  // no chance to clean up
  a2.reset();
  ASSERT_TRUE(status.waitFor(1, "timeouts 1;", 30s)) << status.last(1);
  test::Child a2b(test::agentArgs(2, scenario, url, tmp / "lcm2", "dc"), tmp / "a2b");
  EXPECT_EQ(replay.wait(60s), 0) << replay.err();
  EXPECT_EQ(a1.wait(30s), 0) << a1.err();
  EXPECT_EQ(a2b.wait(30s), 0) << a2b.err();
  // The survivor finished with a valid record; the restarted agent rejoined with a new boot
  // id, started at the ground truth of the moment and produced a valid record of its own.
  EXPECT_TRUE(validRecord(tmp / "lcm", 1, 150));
  EXPECT_TRUE(validRecord(tmp / "lcm2", 2, 40)) << a2b.err();
  EXPECT_EQ(listener.bootIds(2).size(), 2u);
  // The survivor noticed: the peer timed out, then joined again as a new peer (not a restart:
  // it was forgotten).
  const std::string out = a1.out();
  EXPECT_NE(out.find("peer restarts 0, peer timeouts 1"), std::string::npos) << out;
  EXPECT_NE(out.find("cooperation: peers 1"), std::string::npos) << out;
  const auto ate = test::ateOf(tmp / "lcm2", tmp / "eval2");
  ASSERT_EQ(ate.count(2), 1u);
  EXPECT_LT(ate.at(2), 1.0);
}

TEST(AgentProcess, FloodOfJunkIsCountedNotFatal) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 10.0, true);
  const std::string url = test::agentUrl(27802);
  test::SummaryListener listener(url);
  // DC mode: the agent listens on the cooperation channels too; its counters on every summary.
  std::vector<std::string> args = test::agentArgs(1, scenario, url, tmp / "lcm", "dc");
  args.insert(args.end(), {"--set", "agent.counters_period_s=0"});
  test::Child a1(args, tmp / "a1");
  std::this_thread::sleep_for(500ms);
  test::Child replay({CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features", "--rate",
                      "4", "--lcm-url", url, "--quiet"},
                     tmp / "replay");
  transport::BusOptions o;
  o.url = url;
  auto bus = transport::LcmBus::create(o);
  ASSERT_TRUE(bus.ok());
  std::mt19937 rng(7);
  const std::vector<std::string> channels = {"UAV1/IMU",        "UAV1/GT",      "UAV1/FEATURES",
                                             "UAV1/STEREO",     "TEAM/SUMMARY", "UAV1/SHARED",
                                             "UAV1/SHARED_REQ", "UAV2/INDEX"};
  // Valid encodings of sensor messages from a wrong sender, and with absurd content.
  cvslam::imu_t imu{};
  imu.header.agent_id = 5;  // not the replay
  imu.header.utime = 1000;
  auto imu_bytes = transport::encodeMessage(imu);
  ASSERT_TRUE(imu_bytes.ok());
  int junk = 0;
  for (int round = 0; round < 300; ++round) {
    for (const std::string& ch : channels) {
      std::vector<uint8_t> bytes(rng() % 200);
      for (uint8_t& b : bytes) b = static_cast<uint8_t>(rng());
      if (round % 3 == 0 && !imu_bytes->empty()) {
        bytes = *imu_bytes;  // right fingerprint on IMU, wrong type elsewhere, or flipped
        if (round % 2 == 0) bytes[rng() % bytes.size()] ^= 0x5a;
      }
      ASSERT_TRUE((*bus)->publishRaw(ch, bytes.data(), bytes.size()).ok());
      ++junk;
    }
    std::this_thread::sleep_for(3ms);
  }
  EXPECT_EQ(replay.wait(60s), 0) << replay.err();
  EXPECT_EQ(a1.wait(30s), 0) << a1.err();
  EXPECT_TRUE(validRecord(tmp / "lcm", 1, 80));
  // The agent's heartbeat reports what it threw away per channel.
  const cvslam::agent_summary_t s = listener.lastCounted(1);
  int64_t invalid = 0;
  for (std::size_t i = 0; i < s.channel.size(); ++i) invalid += s.invalid[i];
  EXPECT_GE(invalid, junk * 9 / 10) << a1.out();
  EXPECT_NE(a1.out().find("invalid"), std::string::npos);
  const auto ate = test::ateOf(tmp / "lcm", tmp / "eval");
  ASSERT_EQ(ate.count(1), 1u);
  EXPECT_LT(ate.at(1), 1.0);
}

TEST(AgentProcess, BadCommandLinesFailInOneLine) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 2.0, false);
  const std::vector<std::vector<std::string>> bad = {
      {},
      {"--id", "1"},
      {"--id", "0", "--scenario", scenario},
      {"--id", "x", "--scenario", scenario},
      {"--id", "1", "--scenario", scenario, "--calibration", tmp.path()},
      {"--id", "1", "--scenario", scenario, "--mode", "central"},
      {"--id", "1", "--scenario", scenario, "--gs-wait", "0.5"},
      {"--id", "1", "--scenario", scenario, "--mode", "cc", "--starts", "unknown"},
      {"--id", "1", "--scenario", scenario, "--mode", "cc", "--start", "rest"},
      {"--id", "1", "--scenario", scenario, "--filter", "kalman"},
      {"--id", "7", "--scenario", scenario},
      {"--id", "1", "--scenario", tmp / "missing.yaml"},
      {"--id", "1", "--calibration", tmp / "missing"},
      {"--id", "1", "--scenario", scenario, "--idle-exit", "-1"},
      {"--id", "1", "--scenario", scenario, "--bogus"},
      {"--id", "1", "--scenario", scenario, "--lcm-url", "nonsense://x"},
  };
  int n = 0;
  for (const auto& extra : bad) {
    std::vector<std::string> args = {CVSLAM_AGENT_EXE};
    args.insert(args.end(), extra.begin(), extra.end());
    std::string out, err;
    const int status =
        test::run(args, tmp / ("bad" + std::to_string(n++)), &out, &err, std::chrono::seconds(20));
    EXPECT_EQ(status, 2) << extra.size() << " " << err;
    EXPECT_EQ(err.rfind("cvslam_agent: ", 0), 0u) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
  std::string out;
  EXPECT_EQ(test::run({CVSLAM_AGENT_EXE, "--help"}, tmp / "help", &out), 0);
  EXPECT_NE(out.find("usage: cvslam_agent"), std::string::npos);
}

}  // namespace
}  // namespace cvslam
