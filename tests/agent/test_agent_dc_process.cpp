// cvslam_agent --mode dc as real processes (docs/architecture.md, docs/conventions.md; thesis
// §6.6.5): a lockstep run reproduces cvslam_run --mode dc (same trajectories, same cooperation
// log), and a peer that sends non-finite or absurd landmarks is rejected and counted. Ports
// 27810–27819.
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <sstream>
#include <thread>

#include "agent_test_util.h"
#include "cvslam/lcm/coop_convert.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam {
namespace {

using namespace std::chrono_literals;

using test::slurp;

TEST(AgentDcProcess, LockstepReproducesCvslamRunDc) {
  test::TempFolder tmp;
  const std::string scenario = test::coopPair();
  std::string err;
  ASSERT_EQ(test::run({CVSLAM_RUN_EXE, "--scenario", scenario, "--mode", "dc", "--sensing",
                       "features", "--out", tmp / "inproc", "--quiet"},
                      tmp / "run", nullptr, &err),
            0)
      << err;
  const std::string url = test::agentUrl(27810);
  std::vector<std::unique_ptr<test::Child>> agents;
  for (int id : {1, 2}) {
    agents.push_back(std::make_unique<test::Child>(
        std::vector<std::string>{CVSLAM_AGENT_EXE, "--id", std::to_string(id), "--scenario",
                                 scenario, "--mode", "dc", "--lcm-url", url, "--out", tmp / "lcm",
                                 "--idle-exit", "3"},
        tmp / ("a" + std::to_string(id))));
  }
  test::Child replay({CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features",
                      "--lockstep", "--lockstep-timeout", "20", "--lcm-url", url, "--quiet"},
                     tmp / "replay");
  EXPECT_EQ(replay.wait(120s), 0) << replay.err();
  for (auto& a : agents) EXPECT_EQ(a->wait(30s), 0) << a->err();
  for (int id : {1, 2}) {
    const std::string dir = "/agent_" + std::to_string(id);
    EXPECT_EQ(slurp(tmp / ("lcm" + dir + "/trajectory.tum")),
              slurp(tmp / ("inproc" + dir + "/trajectory.tum")))
        << "UAV" << id;
    EXPECT_EQ(slurp(tmp / ("lcm" + dir + "/coop.csv")), slurp(tmp / ("inproc" + dir + "/coop.csv")))
        << "UAV" << id;
    // Both programs record the same configuration (docs/run_format.md).
    const std::string used = slurp(tmp / ("lcm" + dir + "/config_used.yaml"));
    EXPECT_NE(used.find("ci_method:"), std::string::npos) << used;
    EXPECT_EQ(used, slurp(tmp / ("inproc" + dir + "/config_used.yaml"))) << "UAV" << id;
  }
  // Cooperation happened, and its bandwidth is reported per stream.
  EXPECT_NE(slurp(tmp / "lcm/agent_2/coop.csv").find(",fused,"), std::string::npos);
  const auto expected = test::ateOf(tmp / "inproc", tmp / "eval_inproc");
  const auto got = test::ateOf(tmp / "lcm", tmp / "eval_lcm");
  ASSERT_EQ(got.size(), 2u);
  for (int id : {1, 2}) EXPECT_NEAR(got.at(id), expected.at(id), 0.01 * expected.at(id));
  auto stats = readJsonFile(tmp / "lcm/agent_1/stats.json");
  ASSERT_TRUE(stats.ok());
  ASSERT_TRUE(stats->contains("bytes_sent_per_s"));
  const Json& rates = stats->at("bytes_sent_per_s");
  EXPECT_GT(rates.at("SUMMARY").get<double>(), 0.0);
  EXPECT_GT(rates.at("cooperation").get<double>(), 0.0);
  EXPECT_LT(rates.at("cooperation").get<double>(), 10000.0);
}

TEST(AgentDcProcess, NonFiniteAndAbsurdPeerLandmarksAreRejected) {
  test::TempFolder tmp;
  const std::string scenario = test::coopPair();
  const std::string url = test::agentUrl(27811);
  test::Child agent({CVSLAM_AGENT_EXE, "--id", "1", "--scenario", scenario, "--mode", "dc",
                     "--lcm-url", url, "--out", tmp / "lcm", "--idle-exit", "2"},
                    tmp / "a1");
  // A rogue peer (UAV 9): valid summaries, then landmarks at 1e9 m and with NaN.
  transport::BusOptions o;
  o.url = url;
  auto bus = transport::LcmBus::create(o);
  ASSERT_TRUE(bus.ok());
  std::atomic<int64_t> agent_time{-1};
  ASSERT_TRUE(
      (*bus)
          ->subscribe<cvslam::status_t>(
              "UAV1/STATUS", [&](const cvslam::status_t& m) { agent_time = m.processed_utime; })
          .ok());
  ASSERT_TRUE((*bus)->start().ok());
  std::this_thread::sleep_for(500ms);
  test::Child replay({CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features", "--rate",
                      "3", "--lcm-url", url, "--quiet"},
                     tmp / "replay");
  int absurd = 0, nan = 0;
  while (!replay.exited()) {
    const int64_t t = agent_time.load();
    if (t > 0) {
      ASSERT_TRUE(test::publishRogueSummary(**bus, 9, absurd, t, 10));
      coop::SharedLandmarks l;
      l.header = {9, absurd, t};
      l.to_agent = 1;
      l.vehicle_cov_trace = 1.0;
      coop::SharedLandmark lm;
      lm.index = 3;
      lm.p_LinN = Eigen::Vector3d(1e9, 0, 0);  // absurd
      l.landmarks.push_back(lm);
      auto lmsg = transport::toMessage(l);
      ASSERT_TRUE(lmsg.ok());
      ASSERT_TRUE((*bus)->publish("UAV1/SHARED", *lmsg).ok());
      ++absurd;
      // Non-finite: the transport's validation refuses it before the cooperation sees it.
      lmsg->position[0][1] = std::numeric_limits<double>::quiet_NaN();
      auto bytes = transport::encodeMessage(*lmsg);
      if (bytes.ok()) {
        ASSERT_TRUE((*bus)->publishRaw("UAV1/SHARED", bytes->data(), bytes->size()).ok());
        ++nan;
      }
    }
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(replay.wait(5s), 0) << replay.err();
  EXPECT_EQ(agent.wait(30s), 0) << agent.err();
  ASSERT_GT(absurd, 5);
  const std::string out = agent.out();
  // The report counts the absurd ones as invalid in the cooperation.
  const auto pos = out.find("rejected: invalid ");
  ASSERT_NE(pos, std::string::npos) << out;
  EXPECT_GE(std::stoi(out.substr(pos + 18)), absurd / 2) << out;
  // The non-finite ones never got past the transport: counted invalid on UAV1/SHARED.
  const auto inv = out.find(", invalid ");
  ASSERT_NE(inv, std::string::npos) << out;
  EXPECT_GE(std::stoi(out.substr(inv + 10)), nan / 2) << out;
  // Nothing was fused, the estimate is sane.
  EXPECT_NE(out.find("landmarks fused 0"), std::string::npos) << out;
  const auto ate = test::ateOf(tmp / "lcm", tmp / "eval");
  ASSERT_EQ(ate.count(1), 1u);
  EXPECT_LT(ate.at(1), 1.0);
}

}  // namespace
}  // namespace cvslam
