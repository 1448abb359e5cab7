// Recorded runs (docs/transport.md "Recorded runs"): lcm-logger records a team flying in real
// time; `cvslam_replay --log` plays the log's sensor channels in lockstep into fresh agents,
// which reproduce the recorded agents' trajectories byte for byte. Ports 27842–27844.
#include <gtest/gtest.h>
#include <signal.h>

#include "agent_test_util.h"

namespace cvslam {
namespace {

using namespace std::chrono_literals;

TEST(AgentLogProcess, RecordedRunReplayedIntoFreshAgentsGivesTheSameTrajectories) {
  test::TempFolder tmp;
  const std::string scenario = test::coopPair();
  // The logger needs a large receive buffer (docs/architecture.md, LCM practice).
  const std::string url = test::agentUrl(27842) + "&recv_buf_size=16777216";
  const std::string log = tmp / "team.lcmlog";
  test::Child logger({"/usr/bin/lcm-logger", "--lcm-url=" + url, log}, tmp / "logger");
  std::vector<std::unique_ptr<test::Child>> agents;
  for (int id : {1, 2})
    agents.push_back(std::make_unique<test::Child>(test::agentArgs(id, scenario, url, tmp / "orig"),
                                                   tmp / ("a" + std::to_string(id))));
  std::this_thread::sleep_for(500ms);
  test::Child replay({CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features", "--rate",
                      "1", "--lcm-url", url, "--quiet"},
                     tmp / "replay");
  EXPECT_EQ(replay.wait(60s), 0) << replay.err();
  for (auto& a : agents) EXPECT_EQ(a->wait(30s), 0) << a->err();
  ::kill(logger.pid(), SIGINT);
  EXPECT_EQ(logger.wait(10s), 0) << logger.err();
  // Fresh agents, the log's sensor data in lockstep.
  const std::string url2 = test::agentUrl(27843);
  std::vector<std::unique_ptr<test::Child>> fresh;
  for (int id : {1, 2})
    fresh.push_back(std::make_unique<test::Child>(
        test::agentArgs(id, scenario, url2, tmp / "again"), tmp / ("b" + std::to_string(id))));
  test::Child again({CVSLAM_REPLAY_EXE, "--log", log, "--lockstep", "--lcm-url", url2, "--quiet"},
                    tmp / "again");
  EXPECT_EQ(again.wait(60s), 0) << again.err();
  for (auto& a : fresh) EXPECT_EQ(a->wait(30s), 0) << a->err();
  for (int id : {1, 2}) {
    const std::string path = "/agent_" + std::to_string(id) + "/trajectory.tum";
    const std::string original = test::slurp(tmp / ("orig" + path));
    EXPECT_GT(test::poseCount(tmp / ("orig" + path)), 100u);
    EXPECT_EQ(test::slurp(tmp / ("again" + path)), original) << "UAV" << id;
  }
}

TEST(AgentLogProcess, BadLogsGiveOneLineAndStatus2) {
  test::TempFolder tmp;
  std::ofstream(tmp / "empty.lcmlog") << "";
  for (const std::string& log : {tmp / "missing.lcmlog", tmp / "empty.lcmlog"}) {
    std::string err;
    EXPECT_EQ(test::run({CVSLAM_REPLAY_EXE, "--log", log, "--lcm-url", test::agentUrl(27844)},
                        tmp / "bad", nullptr, &err),
              2)
        << log;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
}

}  // namespace
}  // namespace cvslam
