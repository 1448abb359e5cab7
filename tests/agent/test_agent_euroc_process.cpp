// cvslam_agent on EuRoC-format folders (docs/run_format.md): calibration from the folder's
// sensor.yaml files, start at the first ground-truth pose, rendered images through the real
// front end; and a clean end on SIGTERM. Ports 27820–27829.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <thread>

#include "agent_test_util.h"

namespace cvslam {
namespace {

using namespace std::chrono_literals;

TEST(AgentEurocProcess, CalibrationFromTheFolderAndStartAtTheGroundTruth) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 4.0, true);
  std::string err;
  ASSERT_EQ(test::run({CVSLAM_SIMULATE_EXE, "--scenario", scenario, "--out", tmp / "data"},
                      tmp / "sim", nullptr, &err, 120s),
            0)
      << err;
  const std::string url = test::agentUrl(27820) + "&recv_buf_size=16777216";
  test::Child agent({CVSLAM_AGENT_EXE, "--id", "1", "--calibration", tmp / "data/uav1", "--lcm-url",
                     url, "--out", tmp / "lcm", "--idle-exit", "3"},
                    tmp / "a1");
  test::Child replay({CVSLAM_REPLAY_EXE, "--dataset", "1:" + tmp / "data/uav1", "--lockstep",
                      "--lockstep-timeout", "30", "--lcm-url", url, "--quiet"},
                     tmp / "replay");
  EXPECT_EQ(replay.wait(120s), 0) << replay.err();
  EXPECT_EQ(agent.wait(30s), 0) << agent.err();
  EXPECT_NE(agent.out().find("UAV1: 41 frames"), std::string::npos) << agent.out();
  EXPECT_TRUE(std::filesystem::exists(tmp / "lcm/agent_1/frontend.csv"));
  // The one frontend.csv layout of both programs (docs/run_format.md), one row per frame.
  const std::string frontend = test::slurp(tmp / "lcm/agent_1/frontend.csv");
  EXPECT_EQ(frontend.substr(0, frontend.find('\n')),
            "t,observations,predictions,gated_pairs,associated,initialised,front_end_ms,"
            "association_ms,filter_ms,loop_candidates,loop_inliers");
  EXPECT_EQ(std::count(frontend.begin(), frontend.end(), '\n'), 42) << frontend;
  const auto ate = test::ateOf(tmp / "lcm", tmp / "eval");
  ASSERT_EQ(ate.count(1), 1u) << agent.out() << agent.err();
  EXPECT_LT(ate.at(1), 0.5);
}

TEST(AgentEurocProcess, SigtermEndsCleanly) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 4.0, true);
  test::Child agent({CVSLAM_AGENT_EXE, "--id", "2", "--scenario", scenario, "--lcm-url",
                     test::agentUrl(27821), "--out", tmp / "lcm"},
                    tmp / "a2");
  std::this_thread::sleep_for(1s);
  ASSERT_FALSE(agent.exited()) << agent.err();
  kill(agent.pid(), SIGTERM);
  EXPECT_EQ(agent.wait(10s), 0) << agent.err();
  EXPECT_NE(agent.out().find("UAV2: 0 frames"), std::string::npos) << agent.out();
}

}  // namespace
}  // namespace cvslam
