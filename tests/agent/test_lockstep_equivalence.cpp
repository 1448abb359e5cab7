// The same team, in process and as processes: cvslam_run against cvslam_agent × 2 (+ the
// ground station in CC) fed by cvslam_replay --lockstep over loopback multicast must write the
// same run records byte for byte, for every mode, sensing and filter (docs/architecture.md:
// "lockstep reproduces cvslam_run"). Images go through the renderer of each program
// (cvslam_run renders in process, cvslam_replay for the agents), so the two must draw the same
// world with the same noise. A team whose starts are unknown merges by place exchanges over
// the network as it does in process. Ports 27860–27869.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "agent_test_util.h"
#include "test_paths.h"

namespace cvslam {
namespace {

using namespace std::chrono_literals;
using test::slurp;

struct LockstepCase {
  std::string name;
  std::string scenario;  ///< file under config/scenarios
  std::string mode;      ///< single | dc | cc
  std::string sensing;   ///< features | images
  std::string filter;    ///< ekf | nhinf
  std::string seed;      ///< "" = the scenario's
  std::string duration;  ///< [s]
  int port;
  std::string starts = "";  ///< --starts of both programs ("": as the scenario says)
};

/// landmarks.csv without its true_x, true_y, true_z columns: with images only cvslam_run knows
/// them (the surface its renderer drew at the landmark's pixel); the agents have no renderer.
std::string estimatedColumns(const std::string& csv) {
  std::istringstream in(csv);
  std::string line, out;
  while (std::getline(in, line)) {
    // Up to the 7th comma: id, x, y, z, var_x, var_y, var_z.
    std::size_t cut = 0;
    for (int commas = 0; cut < line.size() && !(line[cut] == ',' && ++commas == 7);) ++cut;
    out += line.substr(0, cut) + "\n";
  }
  return out;
}

std::ostream& operator<<(std::ostream& os, const LockstepCase& c) {
  return os << c.name;
}

class LockstepEquivalence : public ::testing::TestWithParam<LockstepCase> {};

TEST_P(LockstepEquivalence, ProcessesWriteTheRecordsOfCvslamRun) {
  const LockstepCase& c = GetParam();
  test::TempFolder tmp;
  const std::string scenario = test::sourceDir() + "/config/scenarios/" + c.scenario;
  std::vector<std::string> common = {"--scenario", scenario, "--duration", c.duration};
  if (!c.seed.empty()) common.insert(common.end(), {"--seed", c.seed});
  std::vector<std::string> starts;
  if (!c.starts.empty()) starts = {"--starts", c.starts};
  const std::vector<std::string> filter = {"--filter", c.filter};
  // cc: every frame waits for the ground station's estimate, however loaded the machine (a
  // process option, recorded in config_used.yaml by both programs).
  const std::vector<std::string> agent_options = {"--set", "agent.cc.gs_wait_s=30"};

  std::vector<std::string> run = {CVSLAM_RUN_EXE, "--mode", c.mode,         "--sensing",
                                  c.sensing,      "--out",  tmp / "inproc", "--quiet"};
  run.insert(run.end(), common.begin(), common.end());
  run.insert(run.end(), filter.begin(), filter.end());
  run.insert(run.end(), starts.begin(), starts.end());
  if (c.mode == "cc") run.insert(run.end(), agent_options.begin(), agent_options.end());
  std::string err;
  ASSERT_EQ(test::run(run, tmp / "run", nullptr, &err), 0) << err;

  const std::string url = test::agentUrl(c.port);
  std::vector<std::unique_ptr<test::Child>> children;
  if (c.mode == "cc") {
    std::vector<std::string> gs = {CVSLAM_GS_EXE, "--agents",  "1,2",         "--lcm-url", url,
                                   "--out",       tmp / "lcm", "--idle-exit", "3"};
    gs.insert(gs.end(), common.begin(), common.end());
    gs.insert(gs.end(), filter.begin(), filter.end());
    // The agents' image landmarks are named by their own ids (cvslam_run chooses by --sensing).
    if (c.sensing == "images") gs.insert(gs.end(), {"--association", "local_ids"});
    children.push_back(std::make_unique<test::Child>(gs, tmp / "gs"));
  }
  for (int id : {1, 2}) {
    std::vector<std::string> agent = test::agentArgs(id, scenario, url, tmp / "lcm", c.mode);
    agent.insert(agent.end(), filter.begin(), filter.end());
    agent.insert(agent.end(), starts.begin(), starts.end());
    agent.insert(agent.end(), {"--duration", c.duration});
    if (!c.seed.empty()) agent.insert(agent.end(), {"--seed", c.seed});
    if (c.mode == "cc") agent.insert(agent.end(), agent_options.begin(), agent_options.end());
    children.push_back(std::make_unique<test::Child>(agent, tmp / ("a" + std::to_string(id))));
  }
  std::vector<std::string> replay = {CVSLAM_REPLAY_EXE,
                                     "--sensing",
                                     c.sensing,
                                     "--lockstep",
                                     "--lockstep-timeout",
                                     "60",
                                     "--lcm-url",
                                     url,
                                     "--quiet",
                                     "--participants",
                                     c.mode == "cc" ? "1,2,0" : "1,2"};
  replay.insert(replay.end(), common.begin(), common.end());
  test::Child player(replay, tmp / "replay");
  EXPECT_EQ(player.wait(600s), 0) << player.err();
  for (auto& child : children) EXPECT_EQ(child->wait(60s), 0) << child->err();

  std::vector<std::string> files = {"trajectory.tum", "ins_trajectory.tum", "states.csv",
                                    "events.csv",     "landmarks.csv",      "config_used.yaml"};
  if (c.mode == "dc") files.push_back("coop.csv");
  // Estimated frames: every verification, and the estimate in the team frame once merged.
  if (c.starts == "unknown")
    files.insert(files.end(), {"relations.csv", "trajectory_team.tum", "truth.csv"});
  for (int id : {1, 2}) {
    const std::string agent = "/agent_" + std::to_string(id) + "/";
    for (const std::string& file : files) {
      std::string inproc = slurp(tmp / ("inproc" + agent + file));
      std::string lcm = slurp(tmp / ("lcm" + agent + file));
      EXPECT_FALSE(inproc.empty()) << "UAV" << id << " " << file;
      if (c.sensing == "images" && file == "landmarks.csv") {
        inproc = estimatedColumns(inproc);
        lcm = estimatedColumns(lcm);
      }
      // EXPECT_TRUE: a failing EXPECT_EQ would print both whole records.
      EXPECT_TRUE(lcm == inproc) << "UAV" << id << " " << file;
    }
    if (c.mode == "cc") {
      for (const char* file : {"trajectory.tum", "states.csv"}) {
        const std::string gs = "/ground_station" + agent + file;
        EXPECT_TRUE(slurp(tmp / ("lcm" + gs)) == slurp(tmp / ("inproc" + gs))) << gs;
      }
    }
  }
}

// Short windows of the configurations in use: every case costs a run in process plus the same
// run as processes. The DC images case is the team of thesis_loop (two UAVs, NH∞, seed 1).
INSTANTIATE_TEST_SUITE_P(
    AllModes, LockstepEquivalence,
    ::testing::Values(LockstepCase{"ImagesSingleEkf", "thesis_loop.yaml", "single", "images", "ekf",
                                   "", "5", 27860},
                      LockstepCase{"ImagesDcNhinfSeed1", "thesis_loop.yaml", "dc", "images",
                                   "nhinf", "1", "8", 27861},
                      LockstepCase{"ImagesDcEkfCoopPair", "coop_pair.yaml", "dc", "images", "ekf",
                                   "", "12", 27862},
                      LockstepCase{"ImagesCcEkfCoopPair", "coop_pair.yaml", "cc", "images", "ekf",
                                   "", "6", 27863},
                      LockstepCase{"FeaturesDcNhinf", "coop_pair.yaml", "dc", "features", "nhinf",
                                   "", "12", 27864},
                      LockstepCase{"FeaturesCcNhinf", "coop_pair.yaml", "cc", "features", "nhinf",
                                   "", "12", 27865},
                      LockstepCase{"FeaturesDcStartsUnknown", "coop_pair.yaml", "dc", "features",
                                   "ekf", "", "12", 27866, "unknown"}),
    [](const ::testing::TestParamInfo<LockstepCase>& info) { return info.param.name; });

}  // namespace
}  // namespace cvslam
