// cvslam_ground_station with cvslam_agent --mode cc as real processes over loopback multicast
// (docs/ground_station.md; thesis §6.3): a lockstep run reproduces cvslam_run --mode cc; the
// agents go on alone when the ground station is killed and hand over to it again when it is
// restarted; a killed agent is dropped by the ground station and rejoins when restarted; bad
// command lines fail in one line. Every step waits on events (STATUS messages, files), not on
// sleeps. Ports 27830–27849, one per test.
#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <mutex>
#include <thread>

#include "agent_test_util.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam {
namespace {

using namespace std::chrono_literals;
using test::slurp;

std::vector<std::string> groundStation(const std::string& scenario, const std::string& url,
                                       const std::string& out) {
  return {CVSLAM_GS_EXE, "--agents", "1,2", "--scenario",  scenario, "--lcm-url",
          url,           "--out",    out,   "--idle-exit", "3",      "--verbose"};
}

/// Once the two agents and the ground station announced themselves on STATUS: the replay of
/// `scenario` at twice real time (the kill tests).
std::unique_ptr<test::Child> replayWhenAllListen(test::StatusListener& status,
                                                 const std::string& scenario,
                                                 const std::string& url, const std::string& log) {
  for (int id : {1, 2})
    if (!status.waitFor(id, "gs:", 20s)) return nullptr;
  if (!status.waitFor(0, "gs: vehicles", 20s)) return nullptr;
  return std::make_unique<test::Child>(
      std::vector<std::string>{CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features",
                               "--rate", "2", "--lcm-url", url, "--quiet"},
      log);
}

TEST(GroundStationProcess, LockstepReproducesCvslamRunCc) {
  test::TempFolder tmp;
  const std::string scenario = test::coopPair();
  std::string err;
  ASSERT_EQ(test::run({CVSLAM_RUN_EXE, "--scenario", scenario, "--mode", "cc", "--sensing",
                       "features", "--out", tmp / "inproc", "--quiet"},
                      tmp / "run", nullptr, &err),
            0)
      << err;
  const std::string url = test::agentUrl(27830);
  test::Child gs(groundStation(scenario, url, tmp / "lcm"), tmp / "gs");
  std::vector<std::unique_ptr<test::Child>> agents;
  for (int id : {1, 2}) {
    // A generous wait: under CI load the estimate must still come for every frame.
    auto args = test::agentArgs(id, scenario, url, tmp / "lcm", "cc");
    args.insert(args.end(), {"--gs-wait", "10"});
    agents.push_back(std::make_unique<test::Child>(args, tmp / ("a" + std::to_string(id))));
  }
  test::Child replay(
      {CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features", "--lockstep",
       "--participants", "1,2,0", "--lockstep-timeout", "30", "--lcm-url", url, "--quiet"},
      tmp / "replay");
  EXPECT_EQ(replay.wait(180s), 0) << replay.err();
  for (auto& a : agents) EXPECT_EQ(a->wait(30s), 0) << a->err();
  EXPECT_EQ(gs.wait(30s), 0) << gs.err();
  // Every frame took the ground station's estimate; the records are those of cvslam_run.
  for (auto& a : agents)
    EXPECT_NE(a->out().find("frames adopted 121, own 0"), std::string::npos) << a->out();
  for (int id : {1, 2}) {
    const std::string agent = "/agent_" + std::to_string(id);
    for (const char* file : {"/trajectory.tum", "/states.csv", "/events.csv", "/landmarks.csv"}) {
      const std::string inproc = slurp(tmp / ("inproc" + agent + file));
      EXPECT_FALSE(inproc.empty()) << file;
      EXPECT_TRUE(slurp(tmp / ("lcm" + agent + file)) == inproc) << "UAV" << id << file;
    }
    for (const char* file : {"/trajectory.tum", "/states.csv"}) {
      const std::string gs_file = "/ground_station" + agent + file;
      EXPECT_TRUE(slurp(tmp / ("lcm" + gs_file)) == slurp(tmp / ("inproc" + gs_file)))
          << "UAV" << id << gs_file;
    }
  }
  EXPECT_TRUE(slurp(tmp / "lcm/ground_station/landmarks.csv") ==
              slurp(tmp / "inproc/ground_station/landmarks.csv"));
  EXPECT_NE(gs.out().find("refused 0 (none)"), std::string::npos) << gs.out();
}

TEST(GroundStationProcess, AgentsGoOnWithoutTheGroundStationWhichTakesOverAfterItsRestart) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 24.0, true);
  std::string err;
  ASSERT_EQ(test::run({CVSLAM_RUN_EXE, "--scenario", scenario, "--sensing", "features", "--out",
                       tmp / "single", "--quiet"},
                      tmp / "run", nullptr, &err),
            0)
      << err;
  const std::string url = test::agentUrl(27831);
  test::StatusListener status(url);
  ASSERT_TRUE(status.ok());
  auto gs = std::make_unique<test::Child>(groundStation(scenario, url, tmp / "gs1"), tmp / "gs1");
  test::Child a1(test::agentArgs(1, scenario, url, tmp / "lcm", "cc"), tmp / "a1");
  test::Child a2(test::agentArgs(2, scenario, url, tmp / "lcm", "cc"), tmp / "a2");
  auto replay = replayWhenAllListen(status, scenario, url, tmp / "replay");
  ASSERT_TRUE(replay) << status.last(0);
  ASSERT_TRUE(status.waitFor(1, "gs: fresh", 20s)) << status.last(1);
  ASSERT_TRUE(status.waitFor(2, "gs: fresh", 20s)) << status.last(2);
  kill(gs->pid(), SIGKILL);  // no goodbye
  gs.reset();
  // The agents notice and go on with their own estimates.
  ASSERT_TRUE(status.waitFor(1, "gs: absent", 20s)) << status.last(1);
  ASSERT_TRUE(status.waitFor(2, "gs: absent", 20s)) << status.last(2);
  test::Child gs2(groundStation(scenario, url, tmp / "gs2"), tmp / "gs2");
  // The new ground station starts each vehicle from the agent's POSE and takes over again.
  EXPECT_TRUE(status.waitFor(1, "gs: fresh", 20s)) << status.last(1);
  EXPECT_TRUE(status.waitFor(2, "gs: fresh", 20s)) << status.last(2);
  EXPECT_EQ(replay->wait(120s), 0) << replay->err();
  EXPECT_EQ(a1.wait(30s), 0) << a1.err();
  EXPECT_EQ(a2.wait(30s), 0) << a2.err();
  EXPECT_EQ(gs2.wait(30s), 0) << gs2.err();
  // No frame lost: every frame of the 24 s at 10 Hz has its pose.
  for (int id : {1, 2})
    EXPECT_GE(test::poseCount(tmp / ("lcm/agent_" + std::to_string(id) + "/trajectory.tum")), 240u);
  // The adoption log shows the hand-over: fresh, then absent, then fresh again.
  for (int id : {1, 2}) {
    const std::string log = slurp(tmp / ("lcm/agent_" + std::to_string(id) + "/coop.csv"));
    const auto absent = log.find(",gs_absent,");
    ASSERT_NE(absent, std::string::npos) << log;
    EXPECT_NE(log.rfind(",gs_fresh,", absent), std::string::npos) << log;
    EXPECT_NE(log.find(",gs_fresh,", absent), std::string::npos) << log;
  }
  EXPECT_NE(gs2.out().find("vehicle starts 2"), std::string::npos) << gs2.out();
  // Alone, each agent is its own filter: every frame it did not take from a ground station is
  // the pose cvslam_run --mode single gives that frame (same observations, same IMU).
  for (int id : {1, 2}) {
    const std::string agent = "/agent_" + std::to_string(id);
    const auto own = test::ownFrames(tmp / ("lcm" + agent + "/coop.csv"));
    ASSERT_GT(own, 0) << "UAV" << id;
    const auto cc = test::tumPoses(tmp / ("lcm" + agent + "/trajectory.tum"));
    const auto single = test::tumPoses(tmp / ("single" + agent + "/trajectory.tum"));
    int same = 0;
    for (const auto& [t, pose] : cc) {
      auto it = single.find(t);
      same += it != single.end() && it->second == pose ? 1 : 0;
    }
    EXPECT_GE(same, own) << "UAV" << id << ": " << own << " own frames, " << same
                         << " equal to single mode";
  }
  // Valid outputs. The ATE against single mode is reported, not asserted: the restarted
  // joint filter's accuracy depends on the instant it restarts (0.11–0.25 m for UAV1 against
  // 0.10 m alone, docs/results/cc_vs_dc.md) — the joint filter's open consistency problem, not the
  // fault behaviour this test is about.
  const auto single = test::ateOf(tmp / "single", tmp / "eval_single");
  const auto cc = test::ateOf(tmp / "lcm", tmp / "eval_cc");
  ASSERT_EQ(single.size(), 2u);
  ASSERT_EQ(cc.size(), 2u);
  for (int id : {1, 2}) {
    EXPECT_TRUE(std::isfinite(cc.at(id))) << "UAV" << id;
    std::printf("UAV%d: ATE with the ground-station restart %.3f m, alone %.3f m\n", id, cc.at(id),
                single.at(id));
  }
}

TEST(GroundStationProcess, AKilledAgentIsDroppedAndRejoinsWhenRestarted) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 24.0, true);
  const std::string url = test::agentUrl(27832);
  test::StatusListener status(url);
  ASSERT_TRUE(status.ok());
  test::Child gs(groundStation(scenario, url, tmp / "lcm"), tmp / "gs");
  test::Child a1(test::agentArgs(1, scenario, url, tmp / "lcm", "cc"), tmp / "a1");
  auto a2 = std::make_unique<test::Child>(test::agentArgs(2, scenario, url, tmp / "lcm", "cc"),
                                          tmp / "a2");
  auto replay = replayWhenAllListen(status, scenario, url, tmp / "replay");
  ASSERT_TRUE(replay) << status.last(0);
  ASSERT_TRUE(status.waitFor(0, "vehicles 1,2", 20s)) << status.last(0);
  ASSERT_TRUE(status.waitFor(2, "gs: fresh", 20s)) << status.last(2);
  kill(a2->pid(), SIGKILL);
  a2.reset();
  // The ground station drops UAV2 after its timeout and goes on with UAV1.
  ASSERT_TRUE(status.waitFor(0, "vehicles 1;", 20s)) << status.last(0);
  test::Child a2b(test::agentArgs(2, scenario, url, tmp / "lcm2", "cc"), tmp / "a2b");
  // Restarted, it starts at the ground truth of the moment; the ground station starts its
  // vehicle from the agent's first POSE and serves it again.
  EXPECT_TRUE(status.waitFor(0, "vehicles 1,2", 20s)) << status.last(0);
  EXPECT_TRUE(status.waitFor(2, "gs: fresh", 20s)) << status.last(2);
  EXPECT_EQ(replay->wait(120s), 0) << replay->err();
  EXPECT_EQ(a1.wait(30s), 0) << a1.err();
  EXPECT_EQ(a2b.wait(30s), 0) << a2b.err();
  EXPECT_EQ(gs.wait(30s), 0) << gs.err();
  EXPECT_GE(test::poseCount(tmp / "lcm/agent_1/trajectory.tum"), 240u);  // UAV1 lost nothing
  EXPECT_GE(test::poseCount(tmp / "lcm2/agent_2/trajectory.tum"), 40u);
  EXPECT_NE(gs.out().find("agent restarts 1"), std::string::npos) << gs.out();
  EXPECT_NE(gs.out().find("vehicle starts 3"), std::string::npos) << gs.out();
  EXPECT_NE(a2b.out().find("last gs fresh"), std::string::npos) << a2b.out();
  const auto ate = test::ateOf(tmp / "lcm2", tmp / "eval2");
  ASSERT_EQ(ate.count(2), 1u);
  EXPECT_LT(ate.at(2), 2.0);
}

TEST(GroundStationProcess, BadCommandLinesFailInOneLine) {
  test::TempFolder tmp;
  const std::string scenario = test::coopPair();
  const std::vector<std::vector<std::string>> bad = {
      {},
      {"--agents", "1,2"},
      {"--agents", "0", "--scenario", scenario},
      {"--agents", "1,x", "--scenario", scenario},
      {"--agents", "1,7", "--scenario", scenario},
      {"--agents", "1", "--scenario", scenario, "--calibration", "1:" + tmp.path()},
      {"--agents", "1", "--calibration", "one:" + tmp.path()},
      {"--agents", "1", "--scenario", scenario, "--filter", "kalman"},
      {"--agents", "1", "--scenario", tmp / "missing.yaml"},
      {"--agents", "1", "--scenario", scenario, "--config", tmp / "missing.yaml"},
      {"--agents", "1", "--scenario", scenario, "--lcm-url", "nonsense://x"},
      {"--agents", "1", "--scenario", scenario, "--bogus"},
  };
  int n = 0;
  for (const auto& extra : bad) {
    std::vector<std::string> args = {CVSLAM_GS_EXE};
    args.insert(args.end(), extra.begin(), extra.end());
    std::string out, err;
    const int status =
        test::run(args, tmp / ("bad" + std::to_string(n++)), &out, &err, std::chrono::seconds(20));
    EXPECT_EQ(status, 2) << n << " " << err;
    EXPECT_EQ(err.rfind("cvslam_ground_station: ", 0), 0u) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
  std::string out;
  EXPECT_EQ(test::run({CVSLAM_GS_EXE, "--help"}, tmp / "help", &out), 0);
  EXPECT_NE(out.find("usage: cvslam_ground_station"), std::string::npos);
}

}  // namespace
}  // namespace cvslam
