// A team whose starts are partly known (docs/merge.md): the agents started in the team's frame
// cooperate in it at once, and one started unknown is merged with them by place exchanges —
// nobody fuses its landmarks before the frame between them is adopted, since its SUMMARY says
// it estimates in a frame of its own.
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "agent_test_util.h"
#include "cvslam/eval/team_evaluation.h"
#include "cvslam/io/run_reader.h"

namespace cvslam {
namespace {

using test::slurp;

/// When agent `self` first adopted a relation to `peer` (relations.csv); +inf if never.
double firstAdoption(const std::string& run, int self, int peer) {
  const std::string path = agentDir(run, self) + "/relations.csv";
  if (!std::ifstream(path).good()) return std::numeric_limits<double>::infinity();
  for (const auto& r : test::csvRows(path))  // t, peer, verdict, ...
    if (r.size() > 2 && std::stoi(r[1]) == peer && r[2] == "adopted") return std::stod(r[0]);
  return std::numeric_limits<double>::infinity();
}

/// team3_aerial with UAV `unknown`'s start unknown (the shipped file has no relative paths),
/// run in DC into DIR/run.
std::string runWithOneStartUnknown(const test::TempFolder& tmp, int unknown) {
  std::string yaml = slurp(test::sourceDir() + "/config/scenarios/team3_aerial.yaml");
  const std::string id = "  - id: " + std::to_string(unknown) + "\n";
  const auto at = yaml.find(id);
  EXPECT_NE(at, std::string::npos);
  if (at == std::string::npos) return "";
  yaml.insert(at + id.size(), "    start: unknown\n");
  const std::string scenario = tmp / ("team3_uav" + std::to_string(unknown) + "_apart.yaml");
  std::ofstream(scenario) << yaml;
  const std::string run = tmp / ("run" + std::to_string(unknown));
  std::string err;
  EXPECT_EQ(
      test::run({CVSLAM_RUN_EXE, "--scenario", scenario, "--mode", "dc", "--out", run, "--quiet"},
                tmp / ("cvslam_run" + std::to_string(unknown)), nullptr, &err),
      0)
      << err;
  return run;
}

class MixedStarts : public ::testing::TestWithParam<int> {};

// UAV2 unknown: the given frame is also the lowest id's. UAV1 unknown: the lowest id starts
// apart, and the team frame is still the given one.
TEST_P(MixedStarts, KnownAgentsShareTheFrameAndMergeTheUnknownOneByPlace) {
  const int unknown = GetParam();
  test::TempFolder tmp;
  const std::string run = runWithOneStartUnknown(tmp, unknown);
  auto info = readRunInfo(run);
  ASSERT_TRUE(info.ok()) << info.status().message();
  ASSERT_EQ(info->frames_in_world.size(), 1u);
  EXPECT_EQ(info->frames_in_world.count(unknown), 1u);

  // The unknown UAV found the team's frame, was right to, and reports in the given frame.
  auto team = evaluateTeam(run, "");
  ASSERT_TRUE(team.ok()) << team.status().message();
  const TeamAgentEvaluation& apart = team->agents[static_cast<std::size_t>(unknown - 1)];
  ASSERT_EQ(apart.id, unknown);
  ASSERT_TRUE(apart.relations && apart.root);
  EXPECT_GE(apart.relations->adopted, 1);
  EXPECT_EQ(apart.relations->wrong_adopted, 0);
  EXPECT_NE(*apart.root, unknown) << "the team frame is the given one";

  std::vector<int> known;
  for (int id : {1, 2, 3})
    if (id != unknown) known.push_back(id);
  for (int self : known) {
    const int other_known = self == known[0] ? known[1] : known[0];
    // Nothing to find between two agents in the given frame.
    EXPECT_EQ(firstAdoption(run, self, other_known), std::numeric_limits<double>::infinity());
    const double apart_adopted = firstAdoption(run, self, unknown);
    int fused_known = 0;
    for (const auto& r :
         test::csvRows(agentDir(run, self) + "/coop.csv")) {  // t, event, peer, count, fused
      ASSERT_GE(r.size(), 5u);
      if (std::stoi(r[4]) == 0) continue;
      const double t = std::stod(r[0]);
      const int peer = std::stoi(r[2]);
      if (peer == other_known) ++fused_known;
      if (peer == unknown)
        EXPECT_GE(t, apart_adopted) << "UAV" << self << " fused UAV" << unknown
                                    << "'s landmarks at " << t << " s, before it adopted its frame";
    }
    EXPECT_GT(fused_known, 0) << "UAV" << self << " and UAV" << other_known
                              << " cooperate in the given frame";
    // With the frames given, a known agent's team frame is its own: no trajectory_team.tum.
    EXPECT_FALSE(std::ifstream(agentDir(run, self) + "/trajectory_team.tum").good());
  }
}

INSTANTIATE_TEST_SUITE_P(OneUnknown, MixedStarts, ::testing::Values(2, 1),
                         [](const ::testing::TestParamInfo<int>& info) {
                           return "Uav" + std::to_string(info.param) + "Unknown";
                         });

}  // namespace
}  // namespace cvslam
